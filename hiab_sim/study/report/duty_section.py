"""The ``energy.*.duty`` section: one design over the duty period with hot windings and the rest's hold.

For a design on the fine grid and the study's duty model (:func:`hiab_sim.study.nlp.task_problem.duty_options`),
every figure exact (switched brake, kinked losses and battery, :mod:`hiab_sim.emla.duty_energy`):

* the battery energy of the cycle (hot drive powers through the shared DC bus) plus the rest's
  (:func:`hiab_sim.emla.battery.rest_battery_energy`): the battery's number;
* the same with R_s at its data-sheet temperature (cold) and without the hold (free rest), so the
  report says what the hot windings and the hold each add;
* the DC-bus drawn energy and the no-regeneration energy at the battery of the cycle;
* per motor: the hold (pose torques, rest energy, brake margin), the winding temperature and
  R_s(T_peak)/R_s,ref, and whether the winding runs away; ``infeasible`` names each motor whose
  winding has no fixed point below its insulation limit or whose brake cannot hold its pose.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hiab_sim.emla import EmlaSet, battery_energy
from hiab_sim.emla.battery import rest_battery_energy
from hiab_sim.emla.duty_energy import DriveDuty, DutyOptions, drive_duty
from hiab_sim.results.energy_sections import DutyEnergy, MotorDuty
from hiab_sim.study.nlp.interface import SampleState


def duty_drives(emlas: EmlaSet, state: SampleState, options: DutyOptions) -> list[DriveDuty]:
    """Each drive's duty model over ``state``'s samples (hot windings and the rest's hold of ``options``, exact)."""
    act, t = state.actuators, state.joints.time
    return [
        drive_duty(p, t, act.force[:, i], act.velocity[:, i], act.acceleration[:, i], options, exact=True)
        for i, p in enumerate(emlas)
    ]


def _battery(emlas: EmlaSet, t: np.ndarray, drives: list[DriveDuty]) -> tuple[float, float]:
    """(cycle, rest) battery energy [J] of drive duties."""
    cycle = battery_energy(t, np.column_stack([d.power for d in drives]), emlas.battery).energy
    rest = rest_battery_energy([d.rest_energy for d in drives], emlas.battery)[0]
    return cycle, rest


def duty_energy(emlas: EmlaSet, state: SampleState, options: DutyOptions) -> DutyEnergy:
    """The duty section of one design (see the module docstring)."""
    t = state.joints.time
    drives = duty_drives(emlas, state, options)
    cycle, rest = _battery(emlas, t, drives)
    by_model: dict[str, float] = {}
    for key, hot, hold in (
        ("cold_windings_free_rest", False, None),
        ("hot_windings_free_rest", True, None),
        ("cold_windings_with_hold", False, options.hold),
    ):
        variant = duty_drives(emlas, state, replace(options, hot=hot, hold=hold))
        by_model[key] = sum(_battery(emlas, t, variant))
    by_model["hot_windings_with_hold"] = cycle + rest
    exact = battery_energy(t, np.column_stack([d.power for d in drives]), emlas.battery)
    motors: dict[str, MotorDuty] = {}
    infeasible: list[str] = []
    for p, d in zip(emlas, drives, strict=True):
        h, w = d.hold, d.winding
        brake = p.brake
        margin = h.brake_margin if h is not None else None
        peak = w.peak if w is not None else None
        motors[p.name] = MotorDuty(
            hold=options.hold or "none",
            rest_energy_J=d.rest_energy,
            rest_copper_energy_J=d.rest_copper_energy,
            rest_torque_Nm=h.rest_torque if h is not None else 0.0,
            first_pose_torque_Nm=h.first_pose_torque if h is not None else float("nan"),
            last_pose_torque_Nm=h.last_pose_torque if h is not None else float("nan"),
            runaway=d.runaway,
            brake_holding_torque_Nm=brake.holding_torque if brake is not None and options.hold == "brake" else None,
            brake_margin=margin,
            mean_winding_temperature_C=float(np.mean(w.temperature)) if w is not None else None,
            peak_winding_temperature_C=peak,
            rest_standby_energy_J=h.standby_power * options.duty.rest_time if h is not None else None,
            peak_resistance_factor=(
                float(p.winding.factor(peak)) if p.winding is not None and peak is not None and options.hot else None
            ),
        )
        if d.runaway:
            limit = p.winding.insulation_limit if p.winding is not None else float("nan")
            infeasible.append(f"{p.name}: thermal runaway, no winding temperature fixed point below {limit:g} deg C")
        if margin is not None and margin < 0:
            infeasible.append(
                f"{p.name}: the holding brake's {brake.holding_torque if brake else float('nan'):g} N m cannot hold "
                f"the pose ({max(abs(h.first_pose_torque), abs(h.last_pose_torque)) if h else float('nan'):.2f} N m)"
            )
    return DutyEnergy(
        hold=options.hold or "none",
        battery_energy_J=cycle + rest,
        cycle_battery_energy_J=cycle,
        rest_battery_energy_J=rest,
        hot_winding_extra_J=cycle + rest - by_model["cold_windings_with_hold"],
        hold_extra_J=cycle + rest - by_model["hot_windings_free_rest"],
        dc_bus_drawn_energy_J=exact.dc_bus_drawn_energy,
        no_regeneration_energy_at_battery_J=exact.no_regeneration_energy_at_battery,
        battery_energy_by_model_J=by_model,
        motors=motors,
        infeasible=tuple(infeasible),
    )

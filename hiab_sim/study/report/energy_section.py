"""Energy sections of a result: battery energy next to ``costf2``, thermal state, hydraulic baseline.

Every result reports both objectives, whichever the solver minimised:

* the battery energy E_bat [J] (:func:`hiab_sim.emla.battery_energy`, exact kinks and exact drive
  losses (:func:`hiab_sim.emla.operating_point` with ``exact=True``), trapezoid rule on the fine
  grid): what the battery delivers through the DC bus the drives share, regeneration of one drive
  feeding the others first. This is the number that is the battery's;
* the paper's cost ``costf2`` = 1/2 Dt sum_k (sum_i P_i)^2 [W^2 s] on the fine grid (a squared
  power, not an energy);
* per actuator the drawn energy int max(P_i, 0) dt and the net energy int P_i dt [J], and with the
  EMLA file's ``drive_losses`` enabled the energy of each loss (transmission, inverter, brake);
* per motor the RMS torque and peak periodic winding temperature over the study's duty
  (back-to-back cycles, no rest, when the study gives none), exact switching;
* the hydraulic baseline: the crane's own cylinders (crane file ``hydraulic_cylinders``) for the
  same rod forces and velocities, with a constant-pressure and a load-sensing supply
  (:func:`hiab_sim.hydraulics.hydraulic_baseline`).

:func:`energy_lines` gives the lines ``hiab-sim optimize`` prints.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from hiab_sim.emla import battery_energy, operating_point, thermal_check
from hiab_sim.emla.battery import battery_power, rest_battery_energy
from hiab_sim.emla.duty_energy import drive_duty
from hiab_sim.emla.model import OperatingPoint
from hiab_sim.emla.thermal import Duty
from hiab_sim.hydraulics import SupplyResult, hydraulic_baseline
from hiab_sim.hydraulics.battery_boundary import battery_boundary_baselines
from hiab_sim.percent import saving_percent
from hiab_sim.quadrature import trapezoid
from hiab_sim.results.energy_sections import (
    ActuatorThermal,
    DesignEnergy,
    EnergyReport,
    HydraulicAtBattery,
    HydraulicBaseline,
    HydraulicDesign,
    HydraulicVariant,
)
from hiab_sim.results.schema import Result
from hiab_sim.study.constraints.thermal_rows import duty_check
from hiab_sim.study.nlp.interface import SampleState
from hiab_sim.study.nlp.objectives import SquaredPowerCost
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.report.duty_section import duty_drives, duty_energy

#: Drive-loss energies reported per actuator when an option of :mod:`hiab_sim.emla.losses` is on
#: (electrical = mechanical + copper + rotor friction + screw viscous + inertial + these).
DRIVE_LOSS_PARTS = ("transmission_loss", "inverter_loss", "brake_coil_power", "brake_held_power")

BATTERY_NOTE = (
    "battery_energy_J is the battery's energy: exact, on the fine grid, through the DC bus the drives share "
    "(regeneration of one drive feeds the others first, inverter and battery efficiencies of the EMLA file); "
    "costf2_W2s is the paper's 1/2 Dt sum (sum_i P_i)^2, a squared power, not an energy"
)


def study_duty(problem: TaskProblem) -> tuple[Duty, str]:
    """The study's duty for the problem's task (its own cycle time), or back-to-back cycles when none is given."""
    settings, cycle = problem.study.energy.duty, problem.task.reference.duration
    if settings is None:
        return Duty(cycle, 0.0), f"none given: back-to-back cycles ({cycle:g} s, no rest)"
    return settings.duty(cycle), settings.describe(cycle, problem.emlas)


def costf2(problem: TaskProblem, state: SampleState) -> float:
    """1/2 Dt sum_k (sum_i P_i)^2 [W^2 s] on ``problem``'s grid, whatever its objective."""
    return SquaredPowerCost(problem.emlas, problem.dt).value(state)


def _exact_operating_points(problem: TaskProblem, state: SampleState) -> list[OperatingPoint]:
    act = state.actuators
    return [
        operating_point(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i], exact=True)
        for i, p in enumerate(problem.emlas)
    ]


def cycle_battery_power(problem: TaskProblem, state: SampleState) -> np.ndarray:
    """The battery power P_bat(t_k) [W] of one cycle at ``state``'s samples, > 0 discharging.

    Each drive's power (with the study's duty model: at the winding temperature of its fixed point,
    :func:`~hiab_sim.study.report.duty_section.duty_drives`; else the exact operating point at R_s,ref)
    through its inverter and the shared DC bus to the battery (:func:`hiab_sim.emla.battery.battery_power`,
    exact kinks). Its trapezoid integral over the samples is the design's ``duty.cycle_battery_energy_J``
    (else ``battery_energy_J``): what the playback's overlay accumulates.
    """
    options = problem.duty_options
    if options is not None:
        power = np.column_stack([d.power for d in duty_drives(problem.emlas, state, options)])
    else:
        power = np.column_stack([op.electrical_power for op in _exact_operating_points(problem, state)])
    return battery_power(power, problem.emlas.battery)[1]


def design_energy(problem: TaskProblem, state: SampleState) -> DesignEnergy:
    """Battery energy (exact and smooth), costf2, per-actuator energies and thermal state of one design."""
    t, battery, act = state.joints.time, problem.emlas.battery, state.actuators
    ops = _exact_operating_points(problem, state)
    exact_power = np.column_stack([op.electrical_power for op in ops])
    exact = battery_energy(t, exact_power, battery)
    smooth = battery_energy(t, state.power, battery, smooth=True)
    smooth_energy = smooth.energy
    duty, _ = study_duty(problem)
    options = problem.duty_options
    duty_section = duty_energy(problem.emlas, state, options) if options is not None else None
    if state.duty is not None:
        smooth_energy += rest_battery_energy([d.rest_energy for d in state.duty], battery)[0]
    losses = {
        p.name: {key: float(trapezoid(getattr(op, key), t)) for key in DRIVE_LOSS_PARTS}
        for p, op in zip(problem.emlas, ops, strict=True)
        if p.losses.transmission_on or p.losses.inverter_on or p.losses.brake_on
    }
    thermal = {}
    for i, p in enumerate(problem.emlas):
        if p.thermal is None:
            continue
        if options is not None:  # hot windings and the rest's hold
            d = drive_duty(p, t, act.force[:, i], act.velocity[:, i], act.acceleration[:, i], options, exact=True)
            c = duty_check(p, d)
        else:
            c = thermal_check(p, t, act.force[:, i], act.velocity[:, i], act.acceleration[:, i], duty, exact=True)
        thermal[p.name] = ActuatorThermal(
            c.rms_torque,
            c.continuous_torque,
            c.peak_temperature,
            c.max_temperature,
            c.torque_margin,
            c.temperature_margin,
        )
    names = problem.emlas.names
    return DesignEnergy(
        battery_energy_J=duty_section.battery_energy_J if duty_section is not None else exact.energy,
        battery_energy_smooth_J=smooth_energy,
        smoothing_bound_J=battery.smoothing_bound(len(names), float(t[-1] - t[0])),
        costf2_W2s=costf2(problem, state),
        drawn_energy_J=dict(zip(names, map(float, exact.drawn_energy), strict=True)),
        net_energy_J=dict(zip(names, map(float, exact.net_energy), strict=True)),
        thermal=thermal or None,
        drive_loss_energy_J=losses or None,
        drive_loss_smoothing_J=(
            smooth.energy - battery_energy(t, exact_power, battery, smooth=True).energy if losses else None
        ),
        duty=duty_section,
    )


def energy_report(fine: TaskProblem, initial: SampleState, optimal: SampleState) -> EnergyReport:
    """The ``energy`` section from the fine-grid states of the initial and optimal designs."""
    e0, e1 = design_energy(fine, initial), design_energy(fine, optimal)
    b = fine.emlas.battery
    return EnergyReport(
        objective=fine.objective.name,
        note=BATTERY_NOTE,
        battery={
            "inverter_efficiency": b.inverter_efficiency,
            "discharge_efficiency": b.discharge_efficiency,
            "charge_efficiency": b.charge_efficiency,
            "smoothing_power_W": b.smoothing_power,
        },
        drive_losses={p.name: p.losses.describe() for p in fine.emlas},
        duty=study_duty(fine)[1],
        initial=e0,
        optimal=e1,
        battery_energy_saved_J=e0.battery_energy_J - e1.battery_energy_J,
        battery_energy_saved_percent=saving_percent(e0.battery_energy_J, e1.battery_energy_J),
    )


def weighted_energy_report(
    reports: list[EnergyReport], weights: Sequence[float], cycles: Sequence[float], periods: Sequence[float]
) -> EnergyReport:
    """A duty mix's ``energy``: each task's battery energy, costf2 and per-actuator energies weighted.

    The thermal state stays per task (each task's ``energy``, its cycle at the study's duty): the
    tasks' weights do not say in which order the crane runs them, which the winding temperature
    depends on. When the weights read as cycles per hour fit in an hour (sum_k w_k T_k <= 3600 s,
    ``cycles`` the tasks' cycle times T_k [s]), the hour's RMS torque of each motor is given too:
    tau_rms,h^2 = sum_k w_k tau_rms,k^2 P_k / 3600 s (``periods`` P_k [s], the duty periods over
    which each task's tau_rms,k was taken), independent of the order: the continuous-torque limit
    of a crane doing that mix for hours.
    """
    w = [float(v) for v in weights]
    work = float(sum(wk * t for wk, t in zip(w, cycles, strict=True)))
    hourly = None
    if work <= 3600.0 and all(r.optimal.thermal for r in reports):
        names = list(reports[0].optimal.thermal or {})
        hourly = {
            name: math.sqrt(
                sum(
                    wk * (r.optimal.thermal or {})[name].rms_torque_Nm ** 2 * period
                    for wk, r, period in zip(w, reports, periods, strict=True)
                )
                / 3600.0
            )
            for name in names
        }

    def total(values: Sequence[float]) -> float:
        return float(sum(wk * v for wk, v in zip(w, values, strict=True)))

    def design(name: str) -> DesignEnergy:
        each = [getattr(r, name) for r in reports]
        return DesignEnergy(
            battery_energy_J=total([d.battery_energy_J for d in each]),
            battery_energy_smooth_J=total([d.battery_energy_smooth_J for d in each]),
            smoothing_bound_J=total([d.smoothing_bound_J for d in each]),
            costf2_W2s=total([d.costf2_W2s for d in each]),
            drawn_energy_J={k: total([d.drawn_energy_J[k] for d in each]) for k in each[0].drawn_energy_J},
            net_energy_J={k: total([d.net_energy_J[k] for d in each]) for k in each[0].net_energy_J},
        )

    initial, optimal = design("initial"), design("optimal")
    saved = initial.battery_energy_J - optimal.battery_energy_J
    return replace(
        reports[0],
        note=reports[0].note + "; a duty mix: every energy weighted by the tasks' weights, thermal state per task",
        duty="per task (see tasks[k].energy)",
        initial=initial,
        optimal=optimal,
        battery_energy_saved_J=saved,
        battery_energy_saved_percent=saving_percent(initial.battery_energy_J, optimal.battery_energy_J),
        hourly_rms_torque_Nm=hourly,
        hourly_work_s=work if hourly is not None else None,
    )


def _variant(s: SupplyResult, names: tuple[str, ...]) -> HydraulicVariant:
    def per(x: np.ndarray) -> dict[str, float]:
        return dict(zip(names, map(float, x), strict=True))

    return HydraulicVariant(
        input_energy_J=s.input_energy,
        input_energy_per_actuator_J=per(s.input_energy_per_actuator),
        system_efficiency=s.system_efficiency,
        delivered_work_J=per(s.delivered_work),
        meter_in_loss_J=per(s.meter_in_loss),
        meter_out_loss_J=per(s.meter_out_loss),
        friction_loss_J=per(s.friction_loss),
        pump_motor_loss_J=s.pump_motor_loss,
        max_load_pressure_Pa=s.max_load_pressure,
        pressure_shortfall_samples=s.pressure_shortfall_samples,
    )


def hydraulic_supplies(fine: TaskProblem, state: SampleState) -> tuple[SupplyResult, SupplyResult] | None:
    """(constant pressure, load sensing) for one design's rod forces and velocities, None without cylinders."""
    cylinders = fine.study.model.hydraulic_cylinders
    if cylinders is None:
        return None
    return hydraulic_baseline(state.joints.time, state.actuators.force, state.actuators.velocity, cylinders)


def hydraulic_report(
    fine: TaskProblem, initial: SampleState, optimal: SampleState, energy: EnergyReport
) -> HydraulicBaseline | None:
    """The ``hydraulic_baseline`` section, or None when the crane file has no ``hydraulic_cylinders``."""
    cylinders = fine.study.model.hydraulic_cylinders
    designs = {}
    for name, state, e in (("initial", initial, energy.initial), ("optimal", optimal, energy.optimal)):
        supplies = hydraulic_supplies(fine, state)
        if supplies is None or cylinders is None:
            return None
        cp, ls = supplies
        emla_cycle = e.duty.cycle_battery_energy_J if e.duty is not None else e.battery_energy_J
        act = state.actuators
        at_battery = {
            b.variant: HydraulicAtBattery(
                cycle_battery_energy_J=b.battery_energy,
                terms_J=b.terms,
                max_pilot_pressure_Pa=b.max_pilot_pressure,
                pressure_shortfall_samples=b.pressure_shortfall_samples,
                emla_saving_percent=saving_percent(b.battery_energy, emla_cycle),
            )
            for b in battery_boundary_baselines(
                state.joints.time, act.force, act.velocity, cylinders, fine.emlas.battery
            )
        }
        designs[name] = HydraulicDesign(
            constant_pressure=_variant(cp, fine.emlas.names),
            load_sensing=_variant(ls, fine.emlas.names),
            emla_battery_energy_J=e.battery_energy_J,
            emla_saving_vs_load_sensing_percent=saving_percent(ls.input_energy, e.battery_energy_J),
            emla_saving_vs_constant_pressure_percent=saving_percent(cp.input_energy, e.battery_energy_J),
            at_battery=at_battery,
            emla_cycle_battery_energy_J=emla_cycle,
        )
    return HydraulicBaseline(
        note=(
            "valve-controlled cylinders of the machine file for the same rod forces and velocities (fine grid): "
            "constant_pressure and load_sensing at the pump motor's electric input, EMLA at the battery; at_battery: "
            "every variant (also pump-controlled EHAs) at the battery over the cycle, against the EMLAs' cycle"
        ),
        supply_pressure_Pa=cylinders.supply_pressure if cylinders is not None else float("nan"),
        initial=designs["initial"],
        optimal=designs["optimal"],
    )


def energy_lines(r: Result) -> list[str]:
    """The energy lines ``hiab-sim optimize`` prints: which number is the battery's, thermal, hydraulics."""
    e = r.energy
    if e is None:
        return []
    # a mix's, or one task's of weight != 1: weighted sums (per hour for weights in cycles per hour)
    summed = "" if not r.tasks else ", the tasks' weighted sum (weights in cycles per hour: per hour)"
    lines = [
        f"objective minimised: {e.objective}",
        f"battery energy (the battery's, shared DC bus){summed}: initial {e.initial.battery_energy_J / 1e3:.4f} kJ, "
        f"optimal {e.optimal.battery_energy_J / 1e3:.4f} kJ (-{e.battery_energy_saved_percent:.2f} %); "
        f"costf2 (squared power, not an energy): initial {e.initial.costf2_W2s:.4e}, "
        f"optimal {e.optimal.costf2_W2s:.4e} W^2 s",
        f"drawn energy per actuator (no regeneration){summed} at the optimum: "
        + ", ".join(f"{k} {v / 1e3:.3f} kJ" for k, v in e.optimal.drawn_energy_J.items()),
    ]
    dd = e.optimal.duty
    if dd is not None:
        m = dd.battery_energy_by_model_J
        lines.append(
            f"duty period at the optimum (hold: {dd.hold}): battery {dd.battery_energy_J / 1e3:.4f} kJ = cycle "
            f"{dd.cycle_battery_energy_J / 1e3:.4f} + rest {dd.rest_battery_energy_J / 1e3:.4f} kJ; hot windings add "
            f"{dd.hot_winding_extra_J:.1f} J, the hold {dd.hold_extra_J:.1f} J (cold windings, free rest: "
            f"{m['cold_windings_free_rest'] / 1e3:.4f} kJ); cycle with no regeneration at all: "
            f"{dd.no_regeneration_energy_at_battery_J / 1e3:.3f} kJ at the battery"
        )
        lines.append(
            "windings at the optimum: "
            + "; ".join(
                f"{k} mean {md.mean_winding_temperature_C:.1f} deg C, R_s x{md.peak_resistance_factor:.3f}"
                for k, md in dd.motors.items()
                if md.mean_winding_temperature_C is not None and md.peak_resistance_factor is not None
            )
        )
        lines += [f"INFEASIBLE at the optimum: {line}" for line in dd.infeasible]
    if e.optimal.thermal:
        parts = [
            f"{k} RMS {th.rms_torque_Nm:.2f}/{th.continuous_torque_Nm:.1f} N m, "
            f"winding {th.peak_winding_temperature_C:.1f}/{th.max_winding_temperature_C:.0f} deg C"
            for k, th in e.optimal.thermal.items()
        ]
        lines.append(f"thermal at the optimum, duty {e.duty}: " + "; ".join(parts))
    first = r.tasks[0].energy if r.tasks else None
    if e.hourly_rms_torque_Nm is not None and first is not None:
        limits = {k: th.continuous_torque_Nm for k, th in (first.optimal.thermal or {}).items()}
        lines.append(
            f"thermal over the mix's hour (weights as cycles per hour, {e.hourly_work_s:.0f} s of work): RMS "
            + ", ".join(f"{k} {v:.2f}/{limits.get(k, float('nan')):.1f} N m" for k, v in e.hourly_rms_torque_Nm.items())
        )
    for task in r.tasks or ():
        if task.energy is not None and task.energy.optimal.thermal:
            worst = min(task.energy.optimal.thermal.items(), key=lambda item: item[1].torque_margin)
            th = worst[1]
            lines.append(
                f"thermal at the optimum, task {task.name} ({task.energy.duty}): tightest {worst[0]} RMS "
                f"{th.rms_torque_Nm:.2f}/{th.continuous_torque_Nm:.1f} N m, winding "
                f"{th.peak_winding_temperature_C:.1f}/{th.max_winding_temperature_C:.0f} deg C"
            )
    h = r.hydraulic_baseline
    if h is not None and h.optimal.at_battery is not None:
        lines.append(
            "hydraulic baselines at the battery, same cycle: "
            + ", ".join(
                f"{k} {v.cycle_battery_energy_J / 1e3:.2f} kJ (EMLA {-v.emla_saving_percent:+.1f} %)"
                for k, v in h.optimal.at_battery.items()
            )
        )
    if h is not None:
        o = h.optimal
        lines.append(
            f"hydraulic baseline (same motion): load sensing {o.load_sensing.input_energy_J / 1e3:.2f} kJ, "
            f"constant pressure {o.constant_pressure.input_energy_J / 1e3:.2f} kJ; EMLA battery uses "
            f"{o.emla_saving_vs_load_sensing_percent:.1f} % / {o.emla_saving_vs_constant_pressure_percent:.1f} % less"
        )
    return lines

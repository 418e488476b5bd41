"""The planner's energy model on the closed loop's samples: the hot windings' R_s and the resampled prediction.

Both evaluate the optimiser's own functions (:mod:`hiab_sim.emla.duty_energy`, :mod:`hiab_sim.emla.model`)
on the planned motion at the physics rate (:mod:`hiab_sim.env.reference`, MuJoCo inverse dynamics of the
plan), so the closed loop is compared with the same model, not with a copy of it.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaSet
from hiab_sim.emla.duty_energy import DutyOptions, drive_duty
from hiab_sim.emla.model import electrical_power
from hiab_sim.env.reference import PlannedMotion


class DutyPlan(Protocol):
    """What the planner's energy model needs of a plan, a crane file's or a machine file's."""

    @property
    def time(self) -> Array: ...  # noqa: D102

    @property
    def emlas(self) -> EmlaSet: ...  # noqa: D102

    @property
    def duty(self) -> DutyOptions | None: ...  # noqa: D102


def hot_resistance(plan: DutyPlan, motion: PlannedMotion, resistance: Array) -> Array | None:
    """R_s [ohm] per physics step (N, n) at the plan's periodic winding temperature, or None without hot windings.

    The planner's coupled winding model (:func:`hiab_sim.emla.duty_energy.drive_duty`) on the plan's own
    fine grid (the motion's samples at the grid's times, the same inverse dynamics), its resistance
    factor R_s(T_k) / R_s,ref interpolated to the physics steps and applied to ``resistance`` (the
    drives' R_s,ref, mismatch included).
    """
    duty = plan.duty
    if duty is None or not duty.hot:
        return None
    grid = plan.time - plan.time[0]
    factors = np.ones((len(motion.time), len(resistance)))
    for i, params in enumerate(plan.emlas):
        if params.winding is None or params.thermal is None:
            continue
        force = np.interp(grid, motion.time, motion.force[:, i])
        velocity = np.interp(grid, motion.time, motion.rod_velocity[:, i])
        acceleration = np.interp(grid, motion.time, motion.rod_acceleration[:, i])
        winding = drive_duty(params, grid, force, velocity, acceleration, duty).winding
        if winding is not None:
            factors[:, i] = np.interp(motion.time, grid, winding.resistance_factor)
    return factors * np.asarray(resistance, dtype=float)[None, :]


#: Physics steps between the samples of :func:`resampled_prediction` (5 ms at the 1 ms step).
RESAMPLE_STEPS = 5


def resampled_prediction(plan: DutyPlan, motion: PlannedMotion) -> float:
    """The planner's energy [J] of the planned motion on a 5 ms grid instead of the optimiser's fine grid.

    The same model as ``result.json``'s number (:func:`hiab_sim.emla.duty_energy.drive_duty` with the
    study's duty, else :func:`hiab_sim.emla.model.electrical_power`, smooth forms, trapezoid rule), on
    the closed loop's own inverse dynamics every ``RESAMPLE_STEPS`` physics steps: the brake's release
    factor changes within tens of milliseconds at the cycle's ends, which the optimiser's grid
    (25 ms on the default study) integrates to about 0.07 %; at 5 ms the value has converged (2 ms
    changes it by 5e-7 on the default study).
    """
    rows = slice(None, None, RESAMPLE_STEPS)
    grid = motion.time[rows]
    total = 0.0
    for i, params in enumerate(plan.emlas):
        samples = (motion.force[rows, i], motion.rod_velocity[rows, i], motion.rod_acceleration[rows, i])
        if plan.duty is None:
            power = electrical_power(params, *samples)
        else:
            power = drive_duty(params, grid, *samples, plan.duty).power
        total += float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(grid)))
    return total

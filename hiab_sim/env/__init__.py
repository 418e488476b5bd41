"""The EMLA-driven crane in closed loop as a dm-control environment.

``load(result_dir, design=..., payload_error=...)`` returns a :class:`dm_control.rl.control.Environment`
whose Physics is the crane regenerated for the design's link lengths with simulated EMLA drives
(:mod:`hiab_sim.env.physics`, :mod:`hiab_sim.emla.drive_sim`) and whose task tracks the optimiser's
plan over the study's cycle (:mod:`hiab_sim.env.task`).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from dm_control.rl import control

from hiab_sim.env.physics import CranePhysics, crane_physics
from hiab_sim.env.plan import DESIGNS, DesignPlan, read_plan
from hiab_sim.env.plant.config import Plant
from hiab_sim.env.reference import PlannedMotion, planned_motion
from hiab_sim.env.task import CraneTrackingTask
from hiab_sim.errors import InvalidInputError

#: Physics step [s]: resolves the mechanics; the drives' current loops are integrated exactly within it.
PHYSICS_TIMESTEP = 1e-3
#: Default current-loop bandwidth [Hz].
CURRENT_BANDWIDTH_HZ = 500.0

_DEFAULT_RESULT: dict[str, Path] = {}


def default_result_dir() -> Path:
    """Optimise the default study once per process (no figures, no video) and return its folder."""
    if "dir" not in _DEFAULT_RESULT:
        from hiab_sim.study.run import run_study

        folder = Path(tempfile.mkdtemp(prefix="hiab_sim_default_"))
        run_study(None, folder, figures=False, progress=None)
        _DEFAULT_RESULT["dir"] = folder
    return _DEFAULT_RESULT["dir"]


def sub_steps(control_timestep: float, physics_timestep: float) -> int:
    """Physics steps per agent step; refuses a physics step [s] outside (0, 0.01] or a control step not its multiple."""
    if not (0.0 < physics_timestep <= 0.01):
        raise InvalidInputError("physics_timestep", physics_timestep, "must lie in (0, 0.01]", "s")
    n_sub = round(control_timestep / physics_timestep)
    if n_sub < 1 or abs(n_sub * physics_timestep - control_timestep) > 1e-9:
        raise InvalidInputError("control_timestep", control_timestep, "must be a multiple of the physics step", "s")
    return n_sub


def episode(
    physics: CranePhysics, task: CraneTrackingTask, duration: float, control_timestep: float, n_sub: int
) -> control.Environment:
    """The dm_control environment of one plan's ``duration`` [s] in agent steps of ``control_timestep`` [s]."""
    steps = round(duration / control_timestep)
    return control.Environment(
        physics, task, time_limit=(steps - 0.5) * control_timestep, n_sub_steps=n_sub, flat_observation=False
    )


def load(
    result_dir: str | Path | None = None,
    *,
    design: str = "optimal",
    payload_error: float = 0.0,
    control_timestep: float = 2 * PHYSICS_TIMESTEP,
    physics_timestep: float = PHYSICS_TIMESTEP,
    current_bandwidth_hz: float = CURRENT_BANDWIDTH_HZ,
    plant: Plant | None = None,
    task: int | None = None,
) -> control.Environment:
    """Closed-loop environment of one design of an ``hiab-sim optimize`` result.

    Args:
        result_dir: Folder with result.json and trajectory.npz; None optimises the default study first.
        design: ``initial`` or ``optimal``.
        payload_error: Relative end-mass error of the simulated crane (0.2: 20 % heavier than planned).
        control_timestep: Agent step [s], a multiple of the physics step.
        physics_timestep: MuJoCo step [s].
        current_bandwidth_hz: Current-loop bandwidth of the drives [Hz] (of the continuous loop).
        plant: The plant's effects (:mod:`hiab_sim.env.plant`); None or every effect off: the planner's model.
        task: The index of a duty mix's task whose plan runs (:func:`hiab_sim.env.plan.read_plan`); None for
            a single-task result.

    Raises:
        InvalidInputError: a value out of range (the field is named), or a duty mix's result without a task.

    """
    plan = read_plan(default_result_dir() if result_dir is None else result_dir, design, task)
    return make_environment(
        plan,
        payload_error=payload_error,
        control_timestep=control_timestep,
        physics_timestep=physics_timestep,
        current_bandwidth_hz=current_bandwidth_hz,
        plant=plant,
    )


def make_environment(
    plan: DesignPlan,
    *,
    payload_error: float = 0.0,
    control_timestep: float = 2 * PHYSICS_TIMESTEP,
    physics_timestep: float = PHYSICS_TIMESTEP,
    current_bandwidth_hz: float = CURRENT_BANDWIDTH_HZ,
    plant: Plant | None = None,
) -> control.Environment:
    """Closed-loop environment of a plan (see :func:`load` for the arguments)."""
    n_sub = sub_steps(control_timestep, physics_timestep)
    motion = planned_motion(plan, physics_timestep)
    physics = crane_physics(plan, motion, physics_timestep, payload_error, current_bandwidth_hz, plant)
    task = CraneTrackingTask(plan, motion, physics.drives.drives.current_limit)
    return episode(physics, task, plan.duration, control_timestep, n_sub)


__all__ = [
    "DESIGNS",
    "CranePhysics",
    "CraneTrackingTask",
    "DesignPlan",
    "PlannedMotion",
    "Plant",
    "load",
    "make_environment",
    "planned_motion",
    "read_plan",
]

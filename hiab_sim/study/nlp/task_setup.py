"""What a task's NLP is set up from before its rows: the duty model of its cycle and the working range to serve."""

from __future__ import annotations

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaSet
from hiab_sim.emla.duty_energy import DutyOptions
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.machines.protocol import StudyMachine
from hiab_sim.study.motion.trajectory import JointTrajectory, Reference
from hiab_sim.study.motion.workspace import describe_point
from hiab_sim.study.references.kinds import ik_start
from hiab_sim.study.spec.study_file import Study
from hiab_sim.study.spec.tasks import Task

#: Where the design must serve the machine's full joint range (``bounds.working_range`` crane or machine), the
#: inverse dynamics sees that range shrunk by this much at both ends [rad or m], so trial points of the line
#: search that violate const_j by a second-order amount stay evaluable; on a machine file a task's reference
#: must lie inside the shrunk range (:func:`check_reference_ranges`).
ID_SLACK = 0.02


def duty_options(study: Study, emlas: EmlaSet, cycle_time: float) -> DutyOptions | None:
    """The duty model of a task of ``cycle_time`` [s], or None for the paper's per-sample model.

    None without a ``duty``, and when no EMLA has winding-resistance data and nothing holds the rest
    (the seed's model: every number as before these options existed).
    """
    settings = study.energy.duty
    if settings is None:
        return None
    options = settings.options(cycle_time, emlas)
    if options.hold is None and not any(p.winding is not None and p.thermal is not None for p in emlas):
        return None
    return options


def working_range(model: StudyMachine, joints: Array, margin: float) -> tuple[tuple[float, float], ...]:
    """Joint range each stroke chain must serve: the samples' range widened by ``margin`` [rad]."""
    out = []
    ranges = model.joint_ranges()
    for j in model.stroke_joints:
        lo, hi = ranges[j]
        out.append((max(lo, float(joints[:, j].min()) - margin), min(hi, float(joints[:, j].max()) + margin)))
    return tuple(out)


def served_ranges(
    study: Study, joints: Array
) -> tuple[tuple[tuple[float, float], ...], tuple[tuple[float, float], ...]]:
    """The ranges each stroke chain must serve (const_j at their ends) and the narrower ones the inverse dynamics sees.

    ``working_range`` crane or machine: the machine's full joint range (so the redesigned machine keeps
    its workspace) and it less :data:`ID_SLACK` at each end; ``reference``: the range of ``joints``
    (T, n) [rad or m] widened by ``working_margin`` and by half of it. The one place that defines the
    range a reference may use: :func:`check_reference_ranges` holds the reference to the second.
    """
    model = study.model
    if study.bounds.working_range in ("crane", "machine"):
        ranges = model.joint_ranges()
        working = tuple(ranges[j] for j in model.stroke_joints)
        return working, tuple((lo + ID_SLACK, hi - ID_SLACK) for lo, hi in working)
    margin = study.bounds.working_margin
    return working_range(model, joints, margin), working_range(model, joints, 0.5 * margin)


def task_label(study: Study, task: Task) -> str:
    """``tasks[0] (name)``: the task as the study file gave it."""
    k = next((i for i, t in enumerate(study.tasks) if t is task), None)
    return "the task" if k is None else f"tasks[{k}] ({task.name})"


def reference_label(study: Study, task: Task) -> str:
    """``tasks[0] (name).reference (file.csv)``: the task's reference as the study file gave it."""
    path = getattr(getattr(task.reference, "table", None), "path", None)
    return f"{task_label(study, task)}.reference ({task.reference.kind if path is None else path})"


def reference_joints(study: Study, task: Task, fine: Reference) -> JointTrajectory:
    """The machine's inverse kinematics of the task's reference sampled on its fine grid (``fine``) [rad or m].

    Raises:
        InvalidInputError: a point out of reach, named by its file, row and columns (a CSV's rows
            first), else by the time of the reference's fit; a singular pose as the IK names it.

    """
    model = study.model
    try:
        return model.inverse_kinematics(fine, ik_start(task.reference, model, fine))
    except InvalidInputError as error:
        row_error = getattr(task.reference, "row_reach_error", lambda _: None)(model)
        if row_error is not None:
            where = f"{task_label(study, task)}.reference: {row_error.field}"
            raise InvalidInputError(where, row_error.value, row_error.allowed, row_error.unit) from None
        reach = model.reach(fine.position)
        bad = np.flatnonzero(reach.status == 1)
        if len(bad):
            i = int(bad[0])
            field = f"{reference_label(study, task)}, its fit, at t = {fine.time[i]:.6g} s"
            raise InvalidInputError(field, describe_point(model, fine.position[i]), reach.reasons[1]) from None
        raise InvalidInputError(
            f"{reference_label(study, task)} ({error.field})", error.value, error.allowed, error.unit
        ) from None


def check_reference_ranges(
    study: Study, task: Task, model: StudyMachine, joints: Array, times: Array, what: str = ""
) -> None:
    """Raise naming the task's reference, time and joint where ``joints`` (T, n) leave the ranges ``model`` accepts.

    ``model``: the machine the inverse dynamics sees (its stroke joints' ranges those of
    :func:`served_ranges`); ``joints`` in rad or m; ``times`` [s]; ``what``: words after the reference's
    name (``, its spline fit,``). A machine file's inverse dynamics checks every sample against these
    ranges; a crane's checks its design's stroke instead (its own message), so a crane file's study is
    not checked here.
    """
    if getattr(model, "crane", None) is not None:
        return
    ranges = np.array(model.joint_ranges(), dtype=float)
    out = (joints < ranges[:, 0]) | (joints > ranges[:, 1])
    if not np.any(out):
        return
    j = int(np.argmax(np.any(out, axis=0)))
    i = int(np.argmax(out[:, j]))
    lo, hi = ranges[j]
    full_lo, full_hi = study.model.joint_ranges()[j]
    unit = model.joint_units[j]
    why = ", the machine's range"
    if (lo, hi) != (full_lo, full_hi):
        why = (
            f", the machine's range [{full_lo:.6g}, {full_hi:.6g}] {unit} less {ID_SLACK:g} {unit} at each end "
            f"(bounds.working_range: {study.bounds.working_range} keeps this margin so the optimiser's trial "
            "points stay evaluable; working_range: reference drops it)"
        )
    raise InvalidInputError(
        f"{reference_label(study, task)}{what} at t = {times[i]:.6g} s, joint {model.joint_names[j]}",
        float(joints[i, j]),
        f"must lie in [{lo:.6g}, {hi:.6g}] {unit}{why}",
        unit,
    )


def start_error(error: InvalidInputError, label: str, model: StudyMachine) -> InvalidInputError:
    """The error of a start point the inverse dynamics refused: ``label`` (the design), the machine's word for it."""
    what = "crane" if getattr(model, "crane", None) is not None else "machine"
    allowed = f"the start is not an admissible {what}: {error.allowed}"
    return InvalidInputError(f"{label} ({error.field})", error.value, allowed, error.unit)


__all__ = [
    "ID_SLACK",
    "check_reference_ranges",
    "duty_options",
    "reference_joints",
    "reference_label",
    "served_ranges",
    "start_error",
    "task_label",
    "working_range",
]

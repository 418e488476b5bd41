"""What a task's NLP is set up from before its rows: the duty model of its cycle and the working range to serve."""

from __future__ import annotations

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaSet
from hiab_sim.emla.duty_energy import DutyOptions
from hiab_sim.study.machines.protocol import StudyMachine
from hiab_sim.study.spec.study_file import Study


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


__all__ = ["duty_options", "working_range"]

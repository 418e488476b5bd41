"""The ``structure`` section of a result: pin loads, buckling utilisation and natural frequencies of both designs."""

from __future__ import annotations

from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.structure.summary import StructureSummary, design_structure
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.report.design_check import DesignCheck


def structure_section(fine: TaskProblem, checks: dict[str, DesignCheck]) -> StructureSummary:
    """Pin loads, buckling utilisation and lowest natural frequencies of both designs on the task's fine grid."""
    out = {}
    for name in ("initial", "optimal"):
        ev = checks[name].evaluation
        joints = JointSamples(ev.joints.position, ev.joints.velocity, ev.joints.acceleration)
        out[name] = design_structure(
            fine.crane,
            fine.emlas,
            crane_lengths(ev.lengths),
            joints,
            ev.actuators.force,
            fine.tcp_force,
            fine.study.structure.buckling_safety_factor,
            fine.task.payload.mass,
        )
    return StructureSummary(initial=out["initial"], optimal=out["optimal"])

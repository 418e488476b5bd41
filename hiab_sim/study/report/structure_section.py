"""The ``structure`` section of a result: pin loads, buckling utilisation and natural frequencies of both designs."""

from __future__ import annotations

from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.structure.machine_structure import machine_design_structure
from hiab_sim.structure.summary import DesignStructure, StructureSummary, design_structure
from hiab_sim.study.machines.machine_model import MachineModel
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.report.design_check import DesignCheck


def structure_section(fine: TaskProblem, checks: dict[str, DesignCheck]) -> StructureSummary:
    """Pin loads, buckling utilisation and lowest natural frequencies of both designs on the task's fine grid.

    A crane file's designs go through its closed-form model (:func:`design_structure`), a machine
    file's through its Newton-Euler path (:func:`machine_design_structure`).
    """
    out: dict[str, DesignStructure] = {}
    for name in ("initial", "optimal"):
        ev = checks[name].evaluation
        joints = JointSamples(ev.joints.position, ev.joints.velocity, ev.joints.acceleration)
        if isinstance(fine.model, MachineModel):
            machine = fine.model.machine_at(ev.lengths)
            out[name] = machine_design_structure(
                machine,
                make_machine_dynamics(machine, None, "newton_euler"),
                fine.emlas,
                joints,
                fine.tcp_force,
                fine.study.structure.buckling_safety_factor,
                fine.task.payload.mass,
                tracked=fine.model.extra,
            )
            continue
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

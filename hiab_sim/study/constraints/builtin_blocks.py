"""The built-in constraint blocks of a task's NLP, registered in their row order (seed eqs. ``const_b``..``const_k``).

Each factory takes the :class:`~hiab_sim.study.nlp.task_problem.TaskProblem` being built and returns its
blocks; :mod:`hiab_sim.study.nlp.task_problem` imports this module once, so these come first in every
problem's rows and blocks registered later (:func:`~hiab_sim.study.constraints.block_registry.register_block`)
follow them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hiab_sim.study.analysis.buildable import buildable_blocks
from hiab_sim.study.constraints import blocks as bl
from hiab_sim.study.constraints.block_registry import register_block
from hiab_sim.study.constraints.brake_rows import brake_blocks
from hiab_sim.study.constraints.machine_structure_rows import MACHINE_ROWS
from hiab_sim.study.constraints.structure_rows import CRANE_ROWS, structure_blocks
from hiab_sim.study.constraints.thermal_rows import thermal_blocks
from hiab_sim.study.motion.workspace import tracked_units
from hiab_sim.study.nlp.interface import ConstraintBlock, PerSampleBlock


def _tracking(p: Any) -> list[ConstraintBlock]:
    """The TCP tracking bands of const_b..const_d, tightened by the problem's band fraction."""
    tol, ref, t = p.study.tracking, p.reference, p.times
    units = tracked_units(p.model)
    return [
        bl.TrackingBand(
            order, t, getattr(ref, order), getattr(tol, order), p.band_fraction, p.model.tracked_names, units
        )
        for order in ("position", "velocity", "acceleration")
    ]


def _structure(p: Any) -> list[PerSampleBlock]:
    """The structural rows: a machine file's through its description, a crane file's in closed form."""
    model, kinds = (p.model, MACHINE_ROWS) if p.study.crane_description is None else (p.crane, CRANE_ROWS)
    return structure_blocks(
        p.study.structure, p.times, model, p.emlas, p.tcp_force, p.fd_step, p.task.payload.mass, kinds
    )


# the built-in blocks, in row order (const_b..const_k, thermal limits, holding brakes, buildable design, structure)
register_block("tracking", _tracking)
register_block("envelope", lambda p: [bl.EnvelopeMargins(p.times, p.emlas, p.envelope_margin)])
register_block("stroke", lambda p: [bl.StrokeLimits(p.times, p.model)])
register_block(
    "joint",
    lambda p: [bl.JointLimits(p.times, p.theta_low, p.theta_up, p.model.joint_names, p.model.joint_units)],
)
register_block(
    "joint_velocity",
    lambda p: [bl.JointVelocityLimits(p.times, np.asarray(p.study.bounds.joint_velocity), p.model.joint_names)],
)
register_block("working_range", lambda p: [bl.WorkingRange(p.model, p.working, p.working_clearance)])
register_block("thermal", lambda p: thermal_blocks(p.emlas, p.study.energy.duty, p.task.reference.duration))
register_block("brake", lambda p: brake_blocks(p.emlas, p.study.energy.duty))
register_block("buildable", lambda p: buildable_blocks(p.study, p.working, p.tightened))
register_block("structure", _structure)

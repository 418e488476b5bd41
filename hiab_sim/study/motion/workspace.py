"""Whether a machine reaches every sample of a reference: its inverse kinematics, a named error at the first miss.

The crane's closed-form IK is :mod:`hiab_sim.study.machines.crane_reach` (re-exported here); a
machine file's is the Newton IK of :class:`hiab_sim.study.machines.machine_model.MachineModel`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.machines.crane_reach import REASONS, PlanarIk, planar_ik
from hiab_sim.study.motion.trajectory import Reference

if TYPE_CHECKING:
    from hiab_sim.study.machines.protocol import StudyMachine


def dense_times(duration: float, step: float = 0.01) -> Array:
    """Times [0, duration] [s] at a step <= ``step`` [s], for reachability checks between grid points."""
    return np.linspace(0.0, duration, max(2, int(np.ceil(duration / step))) + 1)


def tracked_units(model: StudyMachine) -> tuple[str, ...]:
    """The unit of each tracked coordinate: m for the TCP's x and y, a joint's own, rad for an attitude."""
    units = {name: unit for name, unit in zip(model.joint_names, model.joint_units, strict=True)}
    return ("m", "m", *(units.get(name, "rad") for name in model.tracked_names[2:]))


def describe_point(model: StudyMachine, point: Array) -> str:
    """``TCP (x, y) m with xt2 = 0.4 m``: a point of tracked coordinates in words."""
    units = tracked_units(model)
    extra = ", ".join(
        f"{name} = {value:.4g} {unit}"
        for name, value, unit in zip(model.tracked_names[2:], point[2:], units[2:], strict=True)
    )
    return f"TCP ({point[0]:.4g}, {point[1]:.4g}) m" + (f" with {extra}" if extra else "")


def check_workspace(model: StudyMachine | Crane, reference: Reference, where: str = "reference") -> Array:
    """Joints (T, n) of every reference sample by the machine's IK; raise naming the first unreachable time.

    ``model``: the study's machine (a crane description stands for its own, closed-form IK).

    Raises:
        InvalidInputError: a sample out of reach or needing a joint outside its range.

    """
    if isinstance(model, Crane):
        from hiab_sim.study.machines.crane_model import CraneModel  # the crane's model imports its IK from here

        model = CraneModel(model)
    ik = model.reach(reference.position)
    bad = np.flatnonzero(ik.status)
    if len(bad):
        i = int(bad[0])
        raise InvalidInputError(
            f"{where} at t = {reference.time[i]:.6g} s",
            describe_point(model, reference.position[i]),
            f"the point {ik.reasons[int(ik.status[i])]}",
        )
    return np.asarray(ik.joints, dtype=float)


def initial_joints(model: StudyMachine | Crane, reference: Reference) -> Array:
    """Joints (n,) of the first reference sample: the start of the Newton IK continuation."""
    return check_workspace(model, reference)[0]


__all__ = ["REASONS", "PlanarIk", "check_workspace", "dense_times", "describe_point", "initial_joints", "planar_ik"]

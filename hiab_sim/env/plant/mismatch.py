"""The crane and drives the plant really has, when they differ from the planned ones (:class:`Mismatch`).

* End mass (the load, body ``end_mass`` of the crane description): mass and inertia x (1 + e_end),
  centre of mass shifted by the offset (its link frame).
* Every other body: mass and inertia x (1 + e_link), centre of mass shifted by s along its link frame's x.
* EMLA friction: screw viscous b_f and rotor Coulomb tau_f x (1 + e_f).

The controller keeps the planned model; only the simulated plant changes.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hiab_sim.crane.description import Crane, RigidBody, mat3, vec3
from hiab_sim.emla.drive_sim import DriveArrays
from hiab_sim.env.plant.config import Mismatch
from hiab_sim.errors import ConfigError
from hiab_sim.model.drives import SlideDrives

#: Name of the load's body in a crane description.
END_MASS = "end_mass"


def _scaled(body: RigidBody, factor: float, shift: np.ndarray) -> RigidBody:
    return replace(
        body,
        mass=body.mass * factor,
        com=vec3(np.asarray(body.com) + shift),
        inertia=mat3(np.asarray(body.inertia) * factor),
    )


def true_crane(crane: Crane, mismatch: Mismatch) -> Crane:
    """The crane with the mismatch's mass and centre-of-mass errors (module docstring)."""
    if not mismatch.enabled:
        return crane
    if not any(body.name == END_MASS for body in crane.bodies):
        raise ConfigError(f"crane '{crane.name}' has no body '{END_MASS}' for the end-mass mismatch")
    bodies = []
    for body in crane.bodies:
        if body.name == END_MASS:
            bodies.append(_scaled(body, 1.0 + mismatch.end_mass_error, np.asarray(mismatch.end_mass_com_offset_m)))
        else:
            shift = np.array([mismatch.link_com_shift_m, 0.0, 0.0])
            bodies.append(_scaled(body, 1.0 + mismatch.link_mass_error, shift))
    return replace(crane, bodies=tuple(bodies))


def true_drives(drives: DriveArrays, slides: SlideDrives, mismatch: Mismatch) -> tuple[DriveArrays, SlideDrives]:
    """Drive arrays and slide damping with the friction error (module docstring)."""
    if not mismatch.enabled:
        return drives, slides
    factor = 1.0 + mismatch.friction_error
    damping = (slides.damping[0] * factor, slides.damping[1] * factor, slides.damping[2] * factor)
    return (
        replace(drives, coulomb=drives.coulomb * factor, viscous=drives.viscous * factor),
        replace(slides, damping=damping),
    )

"""The crane and drives the plant really has, when they differ from the planned ones (:class:`Mismatch`).

* End mass (the load, body ``end_mass`` of the crane description): mass and inertia x (1 + e_end),
  centre of mass shifted by the offset (its link frame).
* Every other body: mass and inertia x (1 + e_link), centre of mass shifted by s along its link frame's x.
* EMLA friction: screw viscous b_f and rotor Coulomb tau_f x (1 + e_f).

On a machine file (:mod:`hiab_sim.machine`) the same errors act on the machine description
(:func:`true_machine`): every rigid part of every link and every chain body (cylinder, rod, rocker,
coupler) is a link body; the end mass is the study's payload at the TCP (its weight, the load the
plan's TCP force carries, :mod:`hiab_sim.env.machine_plan`), whose force is scaled by (1 + e_end)
and applied at the TCP shifted by the offset in the TCP frame (:class:`hiab_sim.env.tcp_load.TcpLoad`).
A machine file has no body of its own for the load, so a machine with no payload has no end-mass error.

The controller keeps the planned model; only the simulated plant changes.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hiab_sim.crane.description import Crane, RigidBody, mat3, vec3
from hiab_sim.crane.names import LOAD_BODY
from hiab_sim.emla.drive_sim import DriveArrays
from hiab_sim.env.plant.config import Mismatch
from hiab_sim.errors import ConfigError
from hiab_sim.machine import parts
from hiab_sim.machine.description import Machine
from hiab_sim.model.drives import SlideDrives


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
    if not any(body.name == LOAD_BODY for body in crane.bodies):
        raise ConfigError(f"crane '{crane.name}' has no body '{LOAD_BODY}' for the end-mass mismatch")
    bodies = []
    for body in crane.bodies:
        if body.name == LOAD_BODY:
            bodies.append(_scaled(body, 1.0 + mismatch.end_mass_error, np.asarray(mismatch.end_mass_com_offset_m)))
        else:
            shift = np.array([mismatch.link_com_shift_m, 0.0, 0.0])
            bodies.append(_scaled(body, 1.0 + mismatch.link_mass_error, shift))
    return replace(crane, bodies=tuple(bodies))


def _scaled_part(body: parts.RigidBody, mismatch: Mismatch) -> parts.RigidBody:
    """A machine part with the link mass error and the centre-of-mass shift along its frame's x."""
    factor = 1.0 + mismatch.link_mass_error
    return replace(
        body,
        mass=body.mass * factor,
        com=parts.vec3(np.asarray(body.com) + np.array([mismatch.link_com_shift_m, 0.0, 0.0])),
        inertia=parts.mat3(np.asarray(body.inertia) * factor),
    )


def _optional_part(body: parts.RigidBody | None, mismatch: Mismatch) -> parts.RigidBody | None:
    return None if body is None else _scaled_part(body, mismatch)


def true_machine(machine: Machine, mismatch: Mismatch) -> Machine:
    """The machine with the mismatch's link mass and centre-of-mass errors on every part (module docstring)."""
    if not mismatch.enabled:
        return machine
    links = tuple(
        replace(link, parts=tuple(_scaled_part(body, mismatch) for body in link.parts)) for link in machine.links
    )
    chains = []
    for chain in machine.chains:
        act = chain.actuator
        actuator = replace(
            act,
            cylinder_body=_optional_part(act.cylinder_body, mismatch),
            rod_body=_optional_part(act.rod_body, mismatch),
        )
        linkage = chain.linkage
        if linkage is not None:
            linkage = replace(
                linkage,
                rocker_body=_optional_part(linkage.rocker_body, mismatch),
                coupler_body=_optional_part(linkage.coupler_body, mismatch),
            )
        chains.append(replace(chain, actuator=actuator, linkage=linkage))
    return replace(machine, links=links, chains=tuple(chains))


def payload_factor(mismatch: Mismatch) -> float:
    """(1 + e_end): the true payload over the planned one on a machine file (module docstring) [-]."""
    return 1.0 + mismatch.end_mass_error if mismatch.enabled else 1.0


def friction_factor(mismatch: Mismatch) -> float:
    """(1 + e_f): the true EMLA friction over the planned one [-] (1 without a mismatch)."""
    return 1.0 + mismatch.friction_error if mismatch.enabled else 1.0


def true_drive_arrays(drives: DriveArrays, mismatch: Mismatch) -> DriveArrays:
    """Drive arrays with the friction error on the rotor's Coulomb and the screw's viscous friction."""
    if not mismatch.enabled:
        return drives
    factor = friction_factor(mismatch)
    return replace(drives, coulomb=drives.coulomb * factor, viscous=drives.viscous * factor)


def true_drives(drives: DriveArrays, slides: SlideDrives, mismatch: Mismatch) -> tuple[DriveArrays, SlideDrives]:
    """Drive arrays and the crane MJCF's slide damping with the friction error (module docstring)."""
    if not mismatch.enabled:
        return drives, slides
    factor = friction_factor(mismatch)
    damping = (slides.damping[0] * factor, slides.damping[1] * factor, slides.damping[2] * factor)
    return true_drive_arrays(drives, mismatch), replace(slides, damping=damping)

"""Forward kinematics of a machine: world poses of every link, the TCP and each chain's bodies.

Link frames compose along the tree (see :mod:`hiab_sim.machine.description`):
``R = R_parent R_joint motion``, ``p = p_parent + R_parent (p_joint + R_joint t)`` with motion
Rz(q) for a revolute joint and t = (q, 0, 0) for a prismatic one. Each chain's dependent bodies
are placed from the closed-form loop closure (:func:`hiab_sim.machine.kinematics.closure.closure`): the
cylinder frame at the base pivot with x towards the end pivot, the rod frame ``Lc0 + x`` further
along it, and for a linkage the rocker frame (at the rocker pivot, x towards the pin H) and the
coupler frame (at H, x towards the coupler pivot); their rotations are R_P Rz(angle), with P the
driven joint's parent link. Vectorised over samples; world y up; m and rad.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.kinematics.closure import chain_geometry, geometry_closure


@dataclass(frozen=True)
class Frames:
    """World poses at joint samples: rotations (..., 3, 3) and positions (..., 3) [m].

    ``rotation``/``position``: per link name; ``tcp_rotation``/``tcp_position``: the TCP;
    ``bodies``: per (chain, body) with body ``cylinder``, ``rod``, ``rocker``, ``coupler``, a pair
    (rotation, position); ``stroke``: per chain, the actuator stroke x [m].
    """

    rotation: dict[str, Array]
    position: dict[str, Array]
    tcp_rotation: Array
    tcp_position: Array
    bodies: dict[tuple[str, str], tuple[Array, Array]]
    stroke: dict[str, Array]

    def point(self, link: str, local: ArrayLike) -> Array:
        """World position (..., 3) of a point given in a link frame [m]."""
        return self.position[link] + self.rotation[link] @ np.asarray(local, dtype=float)


def rotation_z(angle: Array) -> Array:
    """Rotation matrices about z by ``angle`` [rad], shape (*angle.shape, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros((*np.shape(angle), 3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1], out[..., 2, 2] = c, -s, s, c, 1.0
    return out


def joint_samples(machine: Machine, q: ArrayLike | Mapping[str, ArrayLike]) -> dict[str, Array]:
    """Joint samples by joint name from an array (..., n_joints) in ``machine.joint_names`` order or a mapping."""
    names = machine.joint_names
    if isinstance(q, Mapping):
        missing = sorted(set(names) - set(q))
        if missing:
            raise InvalidInputError("joints", str(missing), f"need every joint of {names}")
        arrays = np.broadcast_arrays(*(np.asarray(q[n], dtype=float) for n in names))
        return dict(zip(names, arrays, strict=True))
    a = np.asarray(q, dtype=float)
    if a.shape[-1:] != (len(names),):
        raise InvalidInputError("joints", f"shape {a.shape}", f"last axis must have {len(names)} entries: {names}")
    return {n: a[..., i] for i, n in enumerate(names)}


def _compose(rp: Array, pp: Array, rotation: Array, position: Array) -> tuple[Array, Array]:
    return rp @ rotation, pp + np.einsum("...ij,...j->...i", rp, position)


def forward_kinematics(machine: Machine, q: ArrayLike | Mapping[str, ArrayLike]) -> Frames:
    """World poses of every link, the TCP and the chains' bodies for joint samples ``q``."""
    joints = joint_samples(machine, q)
    shape = next(iter(joints.values())).shape if joints else ()
    rotation: dict[str, Array] = {}
    position: dict[str, Array] = {}
    for link in machine.links:
        r_joint = np.broadcast_to(np.asarray(link.joint_frame.rotation), (*shape, 3, 3))
        p_joint = np.broadcast_to(np.asarray(link.joint_frame.position), (*shape, 3))
        if link.parent is None:
            rotation[link.name], position[link.name] = r_joint, p_joint
            continue
        value = joints[link.joint]
        if link.joint_kind == "revolute":
            r_local, p_local = r_joint @ rotation_z(value), p_joint
        else:
            slide = np.zeros((*shape, 3))
            slide[..., 0] = value
            r_local, p_local = r_joint, p_joint + np.einsum("...ij,...j->...i", r_joint, slide)
        rotation[link.name], position[link.name] = _compose(
            rotation[link.parent], position[link.parent], r_local, p_local
        )
    tcp_r, tcp_p = _compose(
        rotation[machine.tcp_link],
        position[machine.tcp_link],
        np.broadcast_to(np.asarray(machine.tcp.rotation), (*shape, 3, 3)),
        np.broadcast_to(np.asarray(machine.tcp.position), (*shape, 3)),
    )
    frames = Frames(rotation, position, tcp_r, tcp_p, {}, {})
    for chain in machine.chains:
        _add_chain_bodies(machine, chain.name, joints[chain.joint], frames)
    return frames


def _add_chain_bodies(machine: Machine, name: str, q: Array, frames: Frames) -> None:
    chain = machine.chain(name)
    geo = chain_geometry(machine, chain)
    c = geometry_closure(geo, q)
    frames.stroke[name] = c.length - geo.x0
    if chain.kind == "direct":
        return
    parent = str(machine.joint_link(chain.joint).parent)
    rp = frames.rotation[parent]
    base = chain.pivot("base")
    base_p = frames.point(base.link, base.position)
    cyl_r = rp @ rotation_z(c.angles["cylinder"])
    frames.bodies[(name, "cylinder")] = (cyl_r, base_p)
    offset = np.zeros((*q.shape, 3))
    offset[..., 0] = float(chain.actuator.piston_offset or 0.0) + frames.stroke[name]
    frames.bodies[(name, "rod")] = (cyl_r, base_p + np.einsum("...ij,...j->...i", cyl_r, offset))
    if chain.kind == "linkage":
        rocker = chain.pivot("rocker")
        rocker_p = frames.point(rocker.link, rocker.position)
        rocker_r = rp @ rotation_z(c.angles["rocker"])
        frames.bodies[(name, "rocker")] = (rocker_r, rocker_p)
        arm = np.zeros((*q.shape, 3))
        arm[..., 0] = geo.rocker_length
        pin = rocker_p + np.einsum("...ij,...j->...i", rocker_r, arm)
        frames.bodies[(name, "coupler")] = (rp @ rotation_z(c.angles["coupler"]), pin)


def pin_positions(machine: Machine, frames: Frames, name: str) -> dict[str, Array]:
    """World positions (..., 3) of a chain's pins: its pivots and, for a linkage, the pin H [m]."""
    chain = machine.chain(name)
    out = {p.role: frames.point(p.link, p.position) for p in chain.pivots}
    if chain.kind == "linkage":
        rocker_r, rocker_p = frames.bodies[(name, "rocker")]
        arm = np.array([chain.linkage.rocker_length if chain.linkage else 0.0, 0.0, 0.0])
        out["pin"] = rocker_p + rocker_r @ arm
    elif chain.kind == "triangle":
        out["hinge"] = frames.position[machine.joint_link(chain.joint).name]
    return out

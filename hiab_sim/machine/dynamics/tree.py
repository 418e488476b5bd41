"""A machine as one multibody tree with loop closures: what both inverse-dynamics paths and the MJCF share.

:func:`machine_tree` turns a :class:`~hiab_sim.machine.description.Machine` into rigid bodies in
a tree (parents first) and the pins that close its loops. Nothing here spells a machine's names:
bodies and joints are the file's links and joints, and each chain adds bodies named after it.

Bodies, in this order:

1. the machine's links, as the file lists them; the root is fixed, every other link hangs on its
   parent by its revolute or prismatic joint (joint frame and coordinate as in the description);
2. per chain, in file order:

   - ``triangle`` and ``linkage``: ``<chain>.cylinder``, hinged (joint ``<chain>.base_pin``) at
     the base pivot on the pivot's link, frame axes those of that link at zero hinge angle; and
     ``<chain>.rod``, sliding (joint ``<chain>.stroke``) along the cylinder's x axis, origin at
     ``piston_offset + x``: its coordinate is the stroke x [m] and the rod end sits at
     (``rod_length``, 0, dz) in the rod frame, so the pin-to-pin length is x0 + x;
   - ``linkage`` also: ``<chain>.rocker``, hinged (``<chain>.rocker_pin``) at the rocker pivot on
     the driven joint's parent link, and ``<chain>.coupler``, hinged (``<chain>.link_pin``) on the
     rocker at H = (``rocker_length``, 0, 0);
   - ``direct``: no body; the chain's prismatic joint is the actuator.

Every hinge coordinate of a chain body is its frame's angle from its parent's x axis [rad].

Loop pins (each closes two in-plane coordinates, a ``connect`` equality in MuJoCo): a triangle's
``<chain>.end_pin`` (rod end on the end pivot); a linkage's ``<chain>.rod_pin`` (rod end on the
rocker's H) and ``<chain>.coupler_pin`` (coupler end at (``coupler_length``, 0, dz) on the
coupler pivot of the driven link). Each pin is stated as "point A of body a on point B of body
b"; its force is the one body b applies to body a.

Coordinates: every joint of the tree, in body order. The independent ones are the machine's
joints (the order of :attr:`Machine.joint_names`); the actuated ones are the rod slides (and the
direct chains' joints), in chain order. Every machine joint must be driven by exactly one chain,
so that the actuator forces and the pin forces are determined (square balance).

dz: the out-of-plane offset between the two pivots of a pin (pivot z coordinates in the world at
zero coordinates), so that a 3D model closes its loops exactly; the planar dynamics ignores it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.checks import check_non_negative
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Chain, Machine
from hiab_sim.machine.parts import Pose, RigidBody


@dataclass(frozen=True)
class TreeBody:
    """One rigid body of the tree and the joint that carries it.

    ``position`` (3,) [m] and ``rotation`` (3, 3): the joint frame in the parent body's frame;
    ``kind``: ``fixed`` (the root), ``revolute`` (about the joint frame's z) or ``prismatic``
    (along its x); ``inertia``: the body in its own frame, or None (massless); ``chain``: the
    chain that adds it (None for a machine link).
    """

    name: str
    parent: int
    kind: str
    joint: str
    position: Array
    rotation: Array
    inertia: RigidBody | None
    chain: str | None = None


@dataclass(frozen=True)
class LoopPin:
    """A pin closing a loop: point ``point_a`` (3,) of body ``body_a`` lies on ``point_b`` of ``body_b`` [m]."""

    name: str
    body_a: int
    point_a: Array
    body_b: int
    point_b: Array


@dataclass(frozen=True)
class MachineTree:
    """The machine's bodies in tree order, its loop pins, and which coordinates are independent and actuated.

    ``independent[k]`` / ``actuated[k]``: index of the body whose joint is the k-th machine joint /
    the k-th actuator; ``retracted[k]``: x0 of chain k [m] (0 for a direct chain, whose stroke is
    its joint coordinate).
    """

    machine: Machine
    bodies: tuple[TreeBody, ...]
    loops: tuple[LoopPin, ...]
    independent: tuple[int, ...]
    actuated: tuple[int, ...]
    tcp_body: int
    tcp: Pose

    @property
    def gravity(self) -> float:
        """Gravity g [m/s^2], along -y of the world."""
        return self.machine.gravity

    @property
    def dependent(self) -> tuple[int, ...]:
        """Bodies whose joint coordinate follows from the loops (every non-root body not independent)."""
        return tuple(b for b in range(1, len(self.bodies)) if b not in self.independent)

    def index(self, name: str) -> int:
        """Index of the body of this name."""
        for k, body in enumerate(self.bodies):
            if body.name == name:
                return k
        raise InvalidInputError("body", name, f"unknown body; bodies: {[b.name for b in self.bodies]}")


def actuator_lengths(chain: Chain) -> tuple[float, float]:
    """Piston offset Lc0 and rod length Lc [m] of a triangle's or linkage's actuator."""
    piston, rod = chain.actuator.piston_offset, chain.actuator.rod_length
    if piston is None or rod is None:
        raise AssertionError(f"a {chain.kind} chain has both actuator lengths (validated by the description)")
    return float(piston), float(rod)


def world_z(machine: Machine) -> dict[str, tuple[float, Array]]:
    """Per link: world z of its origin and its world rotation at zero coordinates (z is constant in planar motion)."""
    out: dict[str, tuple[float, Array]] = {}
    for link in machine.links:
        position = np.asarray(link.joint_frame.position, dtype=float)
        rotation = np.asarray(link.joint_frame.rotation, dtype=float)
        if link.parent is None:
            out[link.name] = (float(position[2]), rotation)
        else:
            z, parent = out[link.parent]
            out[link.name] = (z + float((parent @ position)[2]), parent @ rotation)
    return out


def machine_tree(machine: Machine) -> MachineTree:
    """The multibody tree of a machine (see the module docstring).

    Raises:
        InvalidInputError: a moving joint no chain drives (field ``links.<link>.joint``).

    """
    index = {link.name: k for k, link in enumerate(machine.links)}
    bodies: list[TreeBody] = []
    for link in machine.links:
        bodies.append(
            TreeBody(
                name=link.name,
                parent=-1 if link.parent is None else index[link.parent],
                kind=link.joint_kind,
                joint=link.joint,
                position=np.asarray(link.joint_frame.position, dtype=float),
                rotation=np.asarray(link.joint_frame.rotation, dtype=float),
                inertia=link.body,
            )
        )
    driven = {c.joint for c in machine.chains}
    for link in machine.links[1:]:
        if link.joint not in driven:
            raise InvalidInputError(
                f"links.{link.name}.joint", link.joint, "every moving joint needs a chain driving it"
            )
    z = world_z(machine)
    loops: list[LoopPin] = []

    def pivot_z(link: str, point: Array) -> float:
        origin, rotation = z[link]
        return origin + float((rotation @ point)[2])

    def add(
        name: str, parent: int, kind: str, joint: str, position: Array, inertia: RigidBody | None, chain: str
    ) -> int:
        bodies.append(TreeBody(name, parent, kind, joint, np.asarray(position, float), np.eye(3), inertia, chain))
        return len(bodies) - 1

    def hinge_at(chain: Chain, role: str, name: str, pin: str, inertia: RigidBody | None) -> tuple[int, float]:
        """Add ``<chain>.<name>`` hinged at the chain's pivot ``role``; return its index and the pivot's world z [m]."""
        pivot = chain.pivot(role)
        xyz = np.asarray(pivot.position, dtype=float)
        parent = index[pivot.link]
        body = add(f"{chain.name}.{name}", parent, "revolute", f"{chain.name}.{pin}", xyz, inertia, chain.name)
        return body, pivot_z(pivot.link, xyz)

    def close_at(chain: Chain, role: str, pin: str, body: int, length: float, z_from: float) -> None:
        """Close a loop: ``body``'s point ``length`` [m] along its x axis meets the chain's pivot ``role``.

        ``z_from`` is the world z [m] of ``body``'s frame; the point sits at the pivot's height above it.
        """
        pivot = chain.pivot(role)
        xyz = np.asarray(pivot.position, dtype=float)
        end = np.array([length, 0.0, pivot_z(pivot.link, xyz) - z_from])
        loops.append(LoopPin(f"{chain.name}.{pin}", body, end, index[pivot.link], xyz))

    actuated: list[int] = []
    for chain in machine.chains:
        if chain.kind == "direct":
            actuated.append(index[machine.joint_link(chain.joint).name])
            continue
        act = chain.actuator
        piston, rod_length = actuator_lengths(chain)
        cylinder, z_base = hinge_at(chain, "base", "cylinder", "base_pin", act.cylinder_body)
        rod = add(
            f"{chain.name}.rod", cylinder, "prismatic", f"{chain.name}.stroke",
            np.array([piston, 0.0, 0.0]), act.rod_body, chain.name,
        )  # fmt: skip
        actuated.append(rod)
        if chain.kind == "triangle":
            close_at(chain, "end", "end_pin", rod, rod_length, z_base)
            continue
        linkage = chain.linkage
        if linkage is None:
            raise AssertionError("a linkage chain carries its four-bar")
        rocker, z_rocker = hinge_at(chain, "rocker", "rocker", "rocker_pin", linkage.rocker_body)
        coupler = add(
            f"{chain.name}.coupler", rocker, "revolute", f"{chain.name}.link_pin",
            np.array([linkage.rocker_length, 0.0, 0.0]), linkage.coupler_body, chain.name,
        )  # fmt: skip
        rod_end = np.array([rod_length, 0.0, z_rocker - z_base])
        loops.append(LoopPin(f"{chain.name}.rod_pin", rod, rod_end, rocker, np.array([linkage.rocker_length, 0, 0.0])))
        close_at(chain, "coupler", "coupler_pin", coupler, linkage.coupler_length, z_rocker)
    independent = tuple(index[machine.joint_link(j).name] for j in machine.joint_names)
    return MachineTree(
        machine=machine,
        bodies=tuple(bodies),
        loops=tuple(loops),
        independent=independent,
        actuated=tuple(actuated),
        tcp_body=index[machine.tcp_link],
        tcp=machine.tcp,
    )


@dataclass(frozen=True)
class SimulationExtras:
    """Per actuator (chain order): armature [kg] and viscous damping [N s/m] on its actuated joint.

    The armature is the rotor and screw inertia reflected to the rod, J_m k^2 + M_sm (eq.
    ``torque_torque`` with k = 2 pi G / rho); the damping the screw's viscous friction b_f (eq.
    ``torque_force``). With them the actuator force is the motor side, f_x + (J_m k^2 + M_sm) a_x + b_f v_x.
    """

    armature_kg: tuple[float, ...]
    damping_Ns_per_m: tuple[float, ...]

    def __post_init__(self) -> None:
        if len(self.armature_kg) != len(self.damping_Ns_per_m):
            raise InvalidInputError(
                "extras", f"{len(self.armature_kg)} armatures, {len(self.damping_Ns_per_m)} dampings", "one each"
            )
        for k, value in enumerate(self.armature_kg):
            check_non_negative(f"extras.armature_kg[{k}]", value, "kg")
        for k, value in enumerate(self.damping_Ns_per_m):
            check_non_negative(f"extras.damping_Ns_per_m[{k}]", value, "N s/m")


@dataclass(frozen=True)
class PinForces:
    """Forces through every joint and pin over T samples, in the order of :func:`pin_layout`.

    Entry p is the force body ``by[p]`` applies to body ``on[p]`` (the reaction on ``by[p]`` is its
    negative): ``world`` (T, P, 2) [N] in the world plane (x, y); ``local`` (T, P, 3) [N] in the
    frame of ``on[p]`` (its z component is non-zero only for a frame tilted out of the plane).
    ``kinds[p]``: ``hinge`` (a revolute joint of the tree: a pin, no moment about the plane
    normal), ``slide`` (a prismatic joint: its whole in-plane force, actuator force included; its
    moment is not reported, so it is no pin) or ``loop`` (a loop pin).
    """

    names: tuple[str, ...]
    kinds: tuple[str, ...]
    on: tuple[str, ...]
    by: tuple[str, ...]
    world: Array
    local: Array

    def force(self, name: str) -> Array:
        """World force (T, 2) [N] on the pin of this name."""
        if name not in self.names:
            raise InvalidInputError("pin", name, f"unknown pin; pins: {list(self.names)}")
        return self.world[:, self.names.index(name)]


@dataclass(frozen=True)
class MachineActuatorSamples:
    """Actuator samples (T, n) in chain order and the pin forces.

    ``force`` f_x [N] (> 0 extends the actuator), ``velocity`` v_x = dx/dt [m/s],
    ``acceleration`` [m/s^2], ``stroke`` x [m] (0 at the retracted length x0).
    """

    names: tuple[str, ...]
    force: Array
    velocity: Array
    acceleration: Array
    stroke: Array
    pins: PinForces

    @property
    def power(self) -> Array:
        """Mechanical power each actuator delivers to the machine, f_x v_x [W], (T, n)."""
        return self.force * self.velocity


PinLayout = tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], tuple[str, ...]]


def pin_layout(tree: MachineTree) -> PinLayout:
    """Names, kinds, acted-on and acting bodies: every joint of the tree in body order, then the loop pins."""
    names, kinds, on, by = [], [], [], []
    for body in tree.bodies[1:]:
        names.append(body.joint)
        kinds.append("hinge" if body.kind == "revolute" else "slide")
        on.append(body.name)
        by.append(tree.bodies[body.parent].name)
    for loop in tree.loops:
        names.append(loop.name)
        kinds.append("loop")
        on.append(tree.bodies[loop.body_a].name)
        by.append(tree.bodies[loop.body_b].name)
    return tuple(names), tuple(kinds), tuple(on), tuple(by)


def joint_arrays(tree: MachineTree, q: object, dq: object, ddq: object) -> tuple[Array, Array, Array]:
    """Independent joint samples as three (T, n) float arrays, checked finite and in their working range.

    Raises:
        InvalidInputError: wrong shape, NaN or inf, or a position outside the joint's ``joint_range``
            (field: the joint's name).

    """
    names = tree.machine.joint_names
    out = []
    for label, values in (("position", q), ("velocity", dq), ("acceleration", ddq)):
        array = np.atleast_2d(np.asarray(values, dtype=float))
        if array.ndim != 2 or array.shape[1] != len(names):
            raise InvalidInputError(f"joints.{label}", f"shape {array.shape}", f"must be (T, {len(names)}): {names}")
        if not np.all(np.isfinite(array)):
            raise InvalidInputError(f"joints.{label}", "NaN or inf", "must be finite")
        out.append(array)
    if not out[0].shape == out[1].shape == out[2].shape:
        raise InvalidInputError("joints", "mismatched shapes", "position, velocity, acceleration must match")
    links = [tree.machine.joint_link(name) for name in names]
    low, high = np.array([link.joint_range for link in links], dtype=float).reshape(len(names), 2).T
    outside = (out[0] < low) | (out[0] > high)
    if np.any(outside):
        k = int(np.argmax(np.any(outside, axis=0)))  # the first joint (file order) with a sample outside
        column = out[0][:, k]
        raise InvalidInputError(
            names[k],
            float(column[np.argmax(outside[:, k])]),
            f"must lie in [{low[k]:.6g}, {high[k]:.6g}]",
            links[k].unit,
        )
    return out[0], out[1], out[2]


def tcp_force_array(tcp_force: object, samples: int) -> Array:
    """External force on the TCP as (T, 2) [N] in the world plane; zero when None.

    Raises:
        InvalidInputError: a shape other than (2,) or (T, 2), or NaN/inf (field ``tcp_force``).

    """
    if tcp_force is None:
        return np.zeros((samples, 2))
    return np.array(np.broadcast_to(_checked_tcp_force(tcp_force, samples), (samples, 2)), dtype=float)


def tcp_force_complex(tcp_force: object, samples: int) -> complex | NDArray[np.complex128] | None:
    """The same force as :func:`tcp_force_array`, as x + i y [N]: None, one number for (2,), or (T,) for (T, 2)."""
    if tcp_force is None:
        return None
    force = _checked_tcp_force(tcp_force, samples)
    if force.ndim == 1:
        return complex(force[0], force[1])
    out: NDArray[np.complex128] = force[:, 0] + 1j * force[:, 1]
    return out


def _checked_tcp_force(tcp_force: object, samples: int) -> Array:
    force = np.asarray(tcp_force, dtype=float)
    if force.shape not in ((2,), (samples, 2)):
        raise InvalidInputError("tcp_force", f"shape {force.shape}", f"must be (2,) or ({samples}, 2)", "N")
    if not np.all(np.isfinite(force)):
        raise InvalidInputError("tcp_force", "NaN or inf", "must be finite", "N")
    return force

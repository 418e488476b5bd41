"""The force on every pin of every chain along the motion: the analytic path and the common result type.

Pins of a closed chain (frames of :mod:`hiab_sim.crane.description`), each joining a *member* to
the *bracket* link that carries it:

==============  =====================  ===========================  =========================
pin             where                  bracket (force in its frame)  member
==============  =====================  ===========================  =========================
``base_pivot``  cylinder base {Bc}     the chain's parent link       the chain's cylinder
``boom_hinge``  boom hinge {B1}        the chain's parent link       the chain's boom
``rod_end``     rod-end pivot {Tc}     the chain's boom              the chain's rod
==============  =====================  ===========================  =========================

The reported force F is the one the member applies to the bracket through the pin [N], in the
plane of motion (the out-of-plane force is zero: gravity and every acceleration lie in the
plane; the out-of-plane moments are carried by the hinges and not reported here), given in {W}
and in the bracket link's frame.

Analytic path (Newton-Euler, independent of MuJoCo). Every link's wrench W_i = (m_i, f_i), the
wrench the rest of the world must apply to it (Lynch & Park eq. 8.41, in {W} about its origin,
:func:`hiab_sim.dynamics.analytic_id.link_wrenches`, the TCP force taken off the link that
carries the TCP). Cut each chain at its three pins; with P the force of the rod on the boom
at {Tc}:

- the actuator (cylinder + rod, joined by the slide) is held by the base pivot force R_c and
  by -P at {Tc}; its moment about {Bc}: M_pair = (Tc - Bc) x (-P);
- the boom and everything it carries (its subtree of links) is held by the hinge force R_h
  and by P; its moment about {B1}: M_sub = (Tc - B1) x P.

These two scalar equations give P (regular unless the triangle is flat, const_k); then
R_c = f_pair + P and R_h = f_sub - P, and the bracket forces are -R_c, -R_h and P.

The MuJoCo path (:mod:`hiab_sim.structure.pin_loads_mujoco`) reads the same forces from the
loop constraint forces and MuJoCo's body interaction forces; the two agree to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.analytic_id import check_analytic_inputs, link_wrenches
from hiab_sim.dynamics.analytic_kinematics import crane_motion
from hiab_sim.dynamics.checks import tcp_force_samples
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.dynamics.spatial import rotate, rotate_back
from hiab_sim.errors import InvalidInputError
from hiab_sim.structure.actuators import actuators

#: The pins of one chain, in order (see the module docstring).
CHAIN_PINS = ("base_pivot", "boom_hinge", "rod_end")


@dataclass(frozen=True)
class Pin:
    """One pin: ``name`` = ``<chain>.<pin>``, the ``bracket`` link whose frame holds the force, the ``member`` link."""

    name: str
    chain: str
    kind: str
    bracket: str
    member: str


def chain_links(chain: str) -> tuple[str, str, str]:
    """Boom, cylinder and rod link names of a chain (the description's naming)."""
    return f"{chain}_boom", f"{chain}_cylinder", f"{chain}_rod"


def pins(crane: Crane) -> tuple[Pin, ...]:
    """Every pin of every chain, chain by chain, in :data:`CHAIN_PINS` order."""
    out = []
    for chain in crane.chains:
        boom, cylinder, rod = chain_links(chain.name)
        members = {"base_pivot": (chain.parent, cylinder), "boom_hinge": (chain.parent, boom), "rod_end": (boom, rod)}
        for kind in CHAIN_PINS:
            bracket, member = members[kind]
            out.append(Pin(f"{chain.name}.{kind}", chain.name, kind, bracket, member))
    return tuple(out)


def link_parents(crane: Crane) -> dict[str, str]:
    """Parent of every moving link: booms and cylinders on their chain's parent, rods on their cylinder."""
    parents: dict[str, str] = {}
    for chain in crane.chains:
        boom, cylinder, rod = chain_links(chain.name)
        parents.update({boom: chain.parent, cylinder: chain.parent, rod: cylinder})
    for actuator in actuators(crane):
        if actuator.chain is None:
            parents[f"{actuator.name}_rod"] = crane.telescope.parent
    return parents


def subtree(crane: Crane, link: str) -> tuple[str, ...]:
    """``link`` and every link it carries."""
    parents = link_parents(crane)
    out = [link]
    for name in parents:
        ancestor = name
        while ancestor in parents and ancestor != link:
            ancestor = parents[ancestor]
        if ancestor == link and name != link:
            out.append(name)
    return tuple(out)


@dataclass(frozen=True)
class PinLoads:
    """Pin forces along the motion: ``force_world`` and ``force_local`` (T, P, 2) [N] of the members on the brackets."""

    pins: tuple[Pin, ...]
    force_world: Array
    force_local: Array

    @property
    def magnitude(self) -> Array:
        """|F| per sample and pin, (T, P) [N]."""
        return np.hypot(self.force_world[..., 0], self.force_world[..., 1])

    @property
    def direction(self) -> Array:
        """Angle of F from the bracket frame's x axis, (T, P) [rad], in (-pi, pi]."""
        return np.arctan2(self.force_local[..., 1], self.force_local[..., 0])

    def peak(self) -> dict[str, float]:
        """Largest |F| over the samples per pin [N]."""
        return {pin.name: float(v) for pin, v in zip(self.pins, np.max(self.magnitude, axis=0), strict=True)}

    def magnitude_range(self) -> dict[str, float]:
        """Range of |F| (largest minus smallest) over the samples per pin [N]."""
        m = self.magnitude
        return {pin.name: float(v) for pin, v in zip(self.pins, np.ptp(m, axis=0), strict=True)}

    def vector_range(self) -> dict[str, float]:
        """Largest change of the force vector, max_ij |F_i - F_j|, per pin [N] (the fatigue-relevant range).

        For a pin whose load also turns, this exceeds the magnitude range; the stress range of the
        pin's shear section follows it.
        """
        out = {}
        for k, pin in enumerate(self.pins):
            f = self.force_local[:, k]
            out[pin.name] = float(np.max(np.linalg.norm(f[:, None, :] - f[None, :, :], axis=-1)))
        return out

    def most_loaded(self) -> tuple[str, float]:
        """The pin with the largest peak force, and that peak [N]."""
        peak = self.peak()
        name = max(peak, key=lambda k: peak[k])
        return name, peak[name]


def _cross_z(a: Array, b: Array) -> Array:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def analytic_pin_loads(
    crane: Crane, lengths: LinkLengths, joints: JointSamples, tcp_force: ArrayLike | None = None
) -> PinLoads:
    """Pin forces from the link wrenches of the analytic Newton-Euler (see the module docstring).

    Raises:
        InvalidInputError: lengths, joint samples or ``tcp_force`` out of range (the field is named).

    """
    check_analytic_inputs(crane, lengths, joints)
    external = tcp_force_samples(tcp_force, len(joints))
    return pin_forces(crane, lengths, joints.position, joints.velocity, joints.acceleration, external)


def pin_forces(
    crane: Crane, lengths: LinkLengths, position: Array, velocity: Array, acceleration: Array, external: Array | None
) -> PinLoads:
    """:func:`analytic_pin_loads` without input checks (for difference stencils that step past a range end).

    ``external``: TCP force (T, 3) in {W} [N] or None.
    """
    T = position.shape[0]
    motion = crane_motion(crane, lengths, position, velocity, acceleration)
    wrench = link_wrenches(crane, lengths, motion)
    if external is not None:
        carrier = next(f"{a.name}_rod" for a in actuators(crane) if a.chain is None)
        held = motion.links[carrier]
        point = held.position + rotate(held.rotation, np.asarray(crane.tcp_in_telescope_rod.position))
        wrench[carrier] = wrench[carrier] - np.concatenate([np.cross(point, external), external], axis=-1)
    world = np.zeros((T, 3 * len(crane.chains), 3))
    local = np.zeros_like(world)
    frames = {name: link.rotation for name, link in motion.links.items()}
    frames["base"] = np.broadcast_to(np.eye(3), (T, 3, 3))
    for c, chain in enumerate(crane.chains):
        boom, cylinder, rod = chain_links(chain.name)
        pair = wrench[cylinder] + wrench[rod]
        sub = sum((wrench[name] for name in subtree(crane, boom)), start=np.zeros((T, 6)))
        base_pivot = motion.links[cylinder].position
        hinge = motion.links[boom].position
        rod_end = hinge + rotate(motion.links[boom].rotation, np.array([chain.L1, 0.0, 0.0]))
        m_pair = pair[:, 2] - _cross_z(base_pivot, pair[:, 3:])
        m_sub = sub[:, 2] - _cross_z(hinge, sub[:, 3:])
        a1, a2 = rod_end - base_pivot, rod_end - hinge
        det = _cross_z(a1, a2)
        if np.any(np.abs(det) <= 1e-12 * np.hypot(a1[:, 0], a1[:, 1]) * np.hypot(a2[:, 0], a2[:, 1])):
            raise InvalidInputError(f"{chain.name} triangle", "flat", "pin forces need a non-flat triangle (const_k)")
        # (Tc - Bc) x P = -m_pair and (Tc - B1) x P = m_sub, with r x P = r_x P_y - r_y P_x
        px = (-m_pair * a2[:, 0] - a1[:, 0] * m_sub) / det
        py = (-a1[:, 1] * m_sub - a2[:, 1] * m_pair) / det
        p = np.stack([px, py, np.zeros(T)], axis=1)
        forces = {"base_pivot": -(pair[:, 3:] + p), "boom_hinge": -(sub[:, 3:] - p), "rod_end": p}
        for k, kind in enumerate(CHAIN_PINS):
            bracket = chain.parent if kind != "rod_end" else boom
            world[:, 3 * c + k] = forces[kind]
            local[:, 3 * c + k] = rotate_back(frames[bracket], forces[kind])
    return PinLoads(pins(crane), world[..., :2], local[..., :2])

"""Analytic inverse dynamics of the crane: screw-theory Newton-Euler, tip to base, numpy only.

Implements the seed paper's ``[f_x, v_x] = ID(theta, dtheta, ddtheta, robot(Xi))`` (eq.
dynamics) after Petrovic & Mattila (2022), independently of MuJoCo:

1. Loop kinematics (eqs. qus, thetas, dq__, k1_3, 04, Dthetas, DDthetas) and the body twist and
   spatial acceleration of every link, base to tip (:mod:`.analytic_kinematics`).
2. Each link's Newton-Euler wrench in its own frame (Lynch & Park eq. 8.41),

       F_i = G_i (dV_i - [0; R_i^T g]) - ad_{V_i}^T G_i V_i,

   with ``G_i`` the 6x6 spatial inertia of the link (the sum of its rigid bodies, scaled with
   the link lengths by :meth:`hiab_sim.crane.description.Crane.bodies_for`) and ``g = (0, -g, 0)`` in {W}:
   the wrench the rest of the world must apply to link i. Wrenches are then expressed in {W}
   about its origin, where wrenches of different links add.
3. The actuator forces, tip to base. All joint axes are z of {W} and all slides lie in the
   x-y plane, so the in-plane components (f_x, f_y, m_z) carry the actuation:

   - telescope: the rod's wrench (less the TCP force) projected on the slide axis u,
     ``f_t = u . f_rod`` (the slide's constraint force has no component along u);
   - tilt, then lift: each chain is cut at the rod-end pivot {Tc} (seed eq. frames); the pin
     force P that the rod applies to the boom has a normal part from the moment balance of the
     cylinder + rod pair about the base pivot {Bc} (the actuator force and the slide's
     constraint are internal to the pair, so only P has a moment there), and an axial part
     from the moment balance of the boom and everything it carries about the boom hinge {B1}.
     The rod's axial balance then gives the actuator force, ``f = e . f_rod + P . e``, with e
     the unit vector {Bc} -> {Tc}. The lift boom carries the whole tilt chain and telescope.

Forces f_x > 0 extend the actuator; v_x = dx/dt; tcp_force is applied by the environment at
the TCP, in {W} (see :mod:`hiab_sim.dynamics.samples`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane import names
from hiab_sim.crane.description import ClosedChain, Crane, LinkLengths
from hiab_sim.crane.mechanism import check_lengths
from hiab_sim.dynamics.analytic_kinematics import MOVING_LINKS, CraneMotion, crane_motion
from hiab_sim.dynamics.analytic_planar import planar_inverse_dynamics, planar_model
from hiab_sim.dynamics.checks import check_joints, tcp_force_samples
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples
from hiab_sim.dynamics.spatial import newton_euler_wrench, rotate, spatial_inertia, wrench_to_parent


@dataclass(frozen=True)
class LinkInertia:
    """Mass [kg], centre of mass [m] and 6x6 spatial inertia G about the link frame's origin."""

    mass: float
    com: Array
    spatial: Array


@dataclass(frozen=True)
class MechanicalEnergy:
    """Kinetic and potential energy of the crane over T samples, each (T,) [J].

    The potential energy is m g y of every moving body's centre of mass, zero at y = 0 of {W}.
    """

    kinetic: Array
    potential: Array

    @property
    def total(self) -> Array:
        """Kinetic plus potential energy [J]."""
        return self.kinetic + self.potential


def link_inertias(crane: Crane, lengths: LinkLengths) -> dict[str, LinkInertia]:
    """Spatial inertia of every moving link: the sum of its rigid bodies' (Lynch & Park eq. 8.32)."""
    out = {}
    bodies = crane.bodies_for(lengths)
    for link in MOVING_LINKS:
        members = [b for b in bodies if b.link == link]
        mass = sum(b.mass for b in members)
        com = sum((b.mass * np.asarray(b.com) for b in members), start=np.zeros(3)) / mass
        G = sum((spatial_inertia(b.mass, b.com, b.inertia) for b in members), start=np.zeros((6, 6)))
        out[link] = LinkInertia(mass=mass, com=com, spatial=G)
    return out


def analytic_inverse_dynamics(
    crane: Crane, lengths: LinkLengths, joints: JointSamples, tcp_force: ArrayLike | None = None
) -> ActuatorSamples:
    """Actuator forces and velocities from joint samples (seed eq. dynamics), vectorised over T.

    Runs the Newton-Euler solve of this module restricted to the plane of motion
    (:mod:`hiab_sim.dynamics.analytic_planar`), which is exact for the actuator forces and
    about 10x cheaper than the 6D form :func:`spatial_inverse_dynamics`; tests hold the two
    together to round-off.

    Args:
        crane: the crane description.
        lengths: the link-length set Xi (checked with :func:`hiab_sim.crane.mechanism.check_lengths`).
        joints: (theta1 [rad], theta2 [rad], xt2 [m]) samples and their time derivatives.
        tcp_force: force the environment applies at the TCP, in {W} [N], (3,) or (T, 3);
            default zero.

    Returns:
        Forces f_x [N], velocities v_x [m/s], accelerations [m/s^2] and strokes x [m] of the
        lift, tilt and telescope actuators, each (T, 3).

    Raises:
        InvalidInputError: lengths, joint samples or tcp_force out of range (the field is named).

    """
    planar_model(crane, lengths)  # checks the lengths once per (crane, lengths)
    check_joints(crane, lengths, joints)
    external = _external(tcp_force, len(joints))
    force, velocity, acceleration, stroke = planar_inverse_dynamics(
        crane, lengths, joints.position, joints.velocity, joints.acceleration, external
    )
    return ActuatorSamples(force=force, velocity=velocity, acceleration=acceleration, stroke=stroke)


class AnalyticInverseDynamics:
    """:func:`analytic_inverse_dynamics` for one link-length set, with the interface of the MuJoCo path.

    Building it checks the lengths (once per set, :func:`planar_model`); a call evaluates eq. dynamics.
    """

    def __init__(self, crane: Crane, lengths: LinkLengths | None = None) -> None:
        self.crane = crane
        self.lengths = crane.default_lengths if lengths is None else lengths
        planar_model(crane, self.lengths)

    def __call__(self, joints: JointSamples, tcp_force: ArrayLike | None = None) -> ActuatorSamples:
        """Actuator samples [f_x, v_x] = ID(theta, dtheta, ddtheta, robot(Xi)) (eq. dynamics)."""
        return analytic_inverse_dynamics(self.crane, self.lengths, joints, tcp_force=tcp_force)


def spatial_inverse_dynamics(
    crane: Crane, lengths: LinkLengths, joints: JointSamples, tcp_force: ArrayLike | None = None
) -> ActuatorSamples:
    """The same as :func:`analytic_inverse_dynamics`, with 6D twists, wrenches and spatial inertias.

    The reference form of the seed's eq. dynamics (Lynch & Park notation, Petrovic & Mattila
    2022): steps 1-3 of the module docstring on every link's full 6D motion.
    """
    check_analytic_inputs(crane, lengths, joints)
    external = _external(tcp_force, len(joints))
    motion = crane_motion(crane, lengths, joints.position, joints.velocity, joints.acceleration)
    W = link_wrenches(crane, lengths, motion)
    tcp = crane.tcp_in_telescope_rod
    rod = motion.links[names.TELESCOPE_ROD]
    tcp_point = rod.position + rotate(rod.rotation, np.asarray(tcp.position))
    W[names.TELESCOPE_ROD] = W[names.TELESCOPE_ROD] - np.concatenate([np.cross(tcp_point, external), external], axis=-1)

    f_telescope = np.einsum("ti,ti->t", rod.rotation[:, :, 0], W[names.TELESCOPE_ROD][:, 3:])
    tilt_subtree = W[names.TILT_BOOM] + W[names.TELESCOPE_ROD]
    f_tilt = _chain_force(crane.tilt, lengths, motion, W, tilt_subtree)
    lift_subtree = tilt_subtree + W[names.TILT_CYLINDER] + W[names.TILT_ROD] + W[names.LIFT_BOOM]
    f_lift = _chain_force(crane.lift, lengths, motion, W, lift_subtree)

    act = motion.actuators
    return ActuatorSamples(
        force=np.stack([f_lift, f_tilt, f_telescope], axis=1),
        velocity=np.stack([act[n].velocity for n in names.ACTUATOR_NAMES], axis=1),
        acceleration=np.stack([act[n].acceleration for n in names.ACTUATOR_NAMES], axis=1),
        stroke=np.stack([act[n].stroke for n in names.ACTUATOR_NAMES], axis=1),
    )


def link_wrenches(crane: Crane, lengths: LinkLengths, motion: CraneMotion) -> dict[str, Array]:
    """Newton-Euler wrench of every moving link, including gravity, in {W} about its origin.

    Each is (T, 6) = (moment [N m], force [N]): the wrench the rest of the world applies to the
    link, ``F_i = G_i (dV_i - [0; R_i^T g]) - ad_{V_i}^T G_i V_i`` (Lynch & Park eq. 8.41; the
    gravity term is their base-acceleration device, eq. 8.52) mapped to {W} (eq. 3.98).
    """
    gravity = np.array([0.0, -crane.gravity, 0.0])
    out = {}
    for name, inertia in link_inertias(crane, lengths).items():
        link = motion.links[name]
        dV = link.acceleration.copy()
        dV[:, 3:] -= np.einsum("tji,j->ti", link.rotation, gravity)
        body = newton_euler_wrench(inertia.spatial, link.twist, dV)
        out[name] = wrench_to_parent(link.rotation, link.position, body)
    return out


def _moment_z(W: Array, point: Array) -> Array:
    """Moment about z of world wrenches (T, 6) about points (T, 3) [N m]."""
    return W[:, 2] - (point[:, 0] * W[:, 4] - point[:, 1] * W[:, 3])


def _cross_z(a: Array, b: Array) -> Array:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def _chain_force(
    chain: ClosedChain,
    lengths: LinkLengths,
    motion: CraneMotion,
    W: dict[str, Array],
    boom_subtree: Array,
) -> Array:
    """Actuator force of one closed chain from moment balances at {Bc} and {B1} [N].

    ``boom_subtree``: the summed world wrench of the boom and every link it carries.
    """
    boom = motion.links[names.boom_link(chain.name)]
    cylinder = motion.links[names.cylinder_link(chain.name)]
    rod_wrench = W[names.rod_link(chain.name)]
    pair = W[names.cylinder_link(chain.name)] + rod_wrench
    hinge, pivot = boom.position, cylinder.position
    rod_end = hinge + boom.rotation[:, :, 0] * chain.L1
    e = cylinder.rotation[:, :, 0]
    n = np.stack([-e[:, 1], e[:, 0], np.zeros_like(e[:, 0])], axis=1)
    s = getattr(lengths, chain.name).x0 + motion.actuators[chain.name].stroke
    # pair about {Bc}: M = (s e) x (-P) -> P.n = -M / s
    pin_normal = -_moment_z(pair, pivot) / s
    # boom subtree about {B1}: M = (t - h) x (P_e e + P_n n)
    arm = rod_end - hinge
    pin_axial = (_moment_z(boom_subtree, hinge) - pin_normal * _cross_z(arm, n)) / _cross_z(arm, e)
    return np.einsum("ti,ti->t", e, rod_wrench[:, 3:]) + pin_axial


def mechanical_energy(crane: Crane, lengths: LinkLengths, joints: JointSamples) -> MechanicalEnergy:
    """Kinetic energy sum V_i^T G_i V_i / 2 and potential energy sum m_i g y_i of all links [J].

    Used by the power balance sum_j f_j v_j + F_tcp . v_tcp = dE/dt that checks both
    inverse-dynamics paths. Inputs are validated like :func:`analytic_inverse_dynamics`.
    """
    check_analytic_inputs(crane, lengths, joints)
    return state_energy(crane, lengths, joints.position, joints.velocity)


def state_energy(crane: Crane, lengths: LinkLengths, position: Array, velocity: Array) -> MechanicalEnergy:
    """Energy of joint states (T, 3) without range checks, for finite-difference stencils [J].

    A stencil around a state at the end of a joint's working range steps slightly outside it;
    the trigonometry stays valid there as long as the chain's triangle is not flat.
    """
    motion = crane_motion(crane, lengths, position, velocity, np.zeros_like(position))
    kinetic = np.zeros(position.shape[0])
    potential = np.zeros(position.shape[0])
    for name, inertia in link_inertias(crane, lengths).items():
        link = motion.links[name]
        kinetic += 0.5 * np.einsum("ti,ij,tj->t", link.twist, inertia.spatial, link.twist)
        com = link.position + rotate(link.rotation, inertia.com)
        potential += inertia.mass * crane.gravity * com[:, 1]
    return MechanicalEnergy(kinetic=kinetic, potential=potential)


def energy_rate(crane: Crane, lengths: LinkLengths, joints: JointSamples, step: float = 1e-3) -> Array:
    """dE/dt [W] at each sample, from energies alone: a 5-point stencil in time (error O(step^4)).

    E is evaluated along q(t) = q + dq t + ddq t^2 / 2, which has the samples' position, velocity
    and acceleration at t = 0, at t = -2 step .. 2 step [s]. Only positions and velocities enter,
    so this checks the spatial accelerations and the Newton-Euler solve independently.
    """
    check_analytic_inputs(crane, lengths, joints)
    q, dq, ddq = joints.position, joints.velocity, joints.acceleration
    total = [
        state_energy(crane, lengths, q + dq * (k * step) + 0.5 * ddq * (k * step) ** 2, dq + ddq * (k * step)).total
        for k in (-2, -1, 1, 2)
    ]
    return (total[0] - 8.0 * total[1] + 8.0 * total[2] - total[3]) / (12.0 * step)


def tcp_velocity(crane: Crane, lengths: LinkLengths, joints: JointSamples) -> Array:
    """Linear velocity of the TCP point in {W}, (T, 3) [m/s] (for the power of a TCP force)."""
    motion = crane_motion(crane, lengths, joints.position, joints.velocity, joints.acceleration)
    rod = motion.links[names.TELESCOPE_ROD]
    w, v = rod.twist[:, :3], rod.twist[:, 3:]
    local = v + np.cross(w, np.asarray(crane.tcp_in_telescope_rod.position))
    return rotate(rod.rotation, local)


def check_analytic_inputs(crane: Crane, lengths: LinkLengths, joints: JointSamples) -> None:
    """Raise :class:`InvalidInputError` for unusable lengths or joint samples (named field).

    Lengths: :func:`hiab_sim.crane.mechanism.check_lengths` (const_g, const_j, const_k); theta1 and
    theta2: :func:`hiab_sim.crane.mechanism.check_joint_samples` (fields ``theta1``,
    ``theta2``); xt2: the telescope's joint range (field ``xt2``).
    """
    check_lengths(crane, lengths)
    check_joints(crane, lengths, joints)


def _external(tcp_force: ArrayLike | None, n: int) -> Array:
    """TCP force broadcast to (T, 3) [N]; zero when None (checked by :func:`tcp_force_samples`)."""
    force = tcp_force_samples(tcp_force, n)
    return np.zeros((n, 3)) if force is None else force

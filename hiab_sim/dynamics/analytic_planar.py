"""The analytic inverse dynamics restricted to the plane of motion: se(2) twists as complex numbers.

Every joint of the crane turns about an axis parallel to z of {W} or slides in the x-y plane,
so every link's 6D twist lies in the planar subalgebra se(2) of se(3), spanned by
(omega_z, v_x, v_y). The actuator forces do work only against the matching wrench components
(m_z, f_x, f_y); the out-of-plane components (m_x, m_y, f_z) are carried by the joints.
Restricting the 6D Newton-Euler equations of :mod:`hiab_sim.dynamics.analytic_id` to se(2)
is therefore exact for the actuator forces, and each link needs only its mass, the in-plane
position of its centre of mass and its moment of inertia about the z axis through it.

In-plane vectors are complex numbers (x + i y in {W}); a link's planar frame has angle phi and
origin z, and a point r fixed in it moves with

    p = z + e^{i phi} r,   dp = dz + i omega (p - z),   ddp = ddz + (i alpha - omega^2) (p - z),

plus, for a slide at rate dx along the unit direction u, the terms u dx and 2 i omega u dx +
u ddx (Coriolis and slide acceleration). The loop kinematics (eqs. qus, dq__, k1_3, 04,
Dthetas, DDthetas) come from :mod:`hiab_sim.crane.mechanism`, the force solve tip to base is
that of :mod:`hiab_sim.dynamics.analytic_id`. About 10x fewer array operations than the 6D
path: this is the path the optimiser calls.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.crane.description import ClosedChain, Crane, LinkLengths
from hiab_sim.crane.mechanism import check_lengths
from hiab_sim.crane.names import (
    BASE,
    LIFT,
    LIFT_BOOM,
    LIFT_CYLINDER,
    LIFT_ROD,
    TELESCOPE_ROD,
    TILT,
    TILT_BOOM,
    TILT_CYLINDER,
    TILT_ROD,
)

Complex = NDArray[np.complex128]


@dataclass(frozen=True)
class PlanarInertia:
    """A link's mass [kg], in-plane centre of mass in its planar frame [m] and I_zz about it [kg m^2].

    Scalars for one design; per-sample arrays (T,) in a stacked model of many designs
    (:mod:`hiab_sim.dynamics.analytic_batch`), where they broadcast against the samples.
    """

    mass: float | Array
    com: complex | Complex
    inertia: float | Array


@dataclass(frozen=True)
class PlanarModel:
    """Constant planar data of a crane for one link-length set (built once, cached).

    The length-dependent fields (``links`` of cylinders and rods, ``pivot``, ``x0``, ``Lc0``) are
    scalars for one design or per-sample arrays (T,) for a stack of designs.
    """

    links: dict[str, PlanarInertia]
    hinge: dict[str, complex]  # boom hinge of each chain in its parent's planar frame [m]
    pivot: dict[str, complex | Complex]  # cylinder base pivot of each chain in its parent's planar frame [m]
    x0: dict[str, float | Array]  # retracted pin-to-pin length Lc0 + Lc of each chain [m]
    Lc0: dict[str, float | Array]  # piston frame offset of each chain [m]
    telescope_origin: complex  # {P22} origin in the tilt boom's planar frame [m]
    telescope_axis: complex  # unit slide direction in the tilt boom's planar frame
    tcp: complex  # TCP in the telescope rod's planar frame (axes of the tilt boom) [m]


def _complex(v: Array) -> complex:
    return complex(float(v[0]), float(v[1]))


@functools.lru_cache(maxsize=64)
def planar_model(crane: Crane, lengths: LinkLengths) -> PlanarModel:
    """Project the crane's bodies and geometry onto the plane (checks the lengths once)."""
    check_lengths(crane, lengths)
    tele = crane.telescope
    R0 = np.asarray(tele.cylinder_frame.rotation)
    # Rotation of each link's frame relative to its planar frame (identity but for the telescope rod).
    relative = {TELESCOPE_ROD: R0}
    groups: dict[str, list[tuple[float, Array, Array]]] = {}
    for body in crane.bodies_for(lengths):
        if body.link == BASE:
            continue
        R = relative.get(body.link, np.eye(3))
        groups.setdefault(body.link, []).append(
            (body.mass, R @ np.asarray(body.com), R @ np.asarray(body.inertia) @ R.T)
        )
    links = {}
    for name, members in groups.items():
        mass = sum(m for m, _, _ in members)
        com = sum((m * c for m, c, _ in members), start=np.zeros(3)) / mass
        izz = sum(inertia[2, 2] + m * float(np.sum((c[:2] - com[:2]) ** 2)) for m, c, inertia in members)
        links[name] = PlanarInertia(mass=mass, com=_complex(com), inertia=izz)
    axis = R0[:, 0]
    return PlanarModel(
        links=links,
        hinge={c.name: _complex(c.boom_hinge) for c in crane.chains},
        pivot={c.name: _complex(c.base_pivot(getattr(lengths, c.name))) for c in crane.chains},
        x0={c.name: getattr(lengths, c.name).x0 for c in crane.chains},
        Lc0={c.name: getattr(lengths, c.name).Lc0 for c in crane.chains},
        telescope_origin=_complex(np.asarray(tele.cylinder_frame.position)),
        telescope_axis=_complex(axis) / abs(_complex(axis)),
        tcp=_complex(R0 @ np.asarray(crane.tcp_in_telescope_rod.position)),
    )


@dataclass
class _Frame:
    """Planar frame motion, each (T,): origin z, dz, ddz and unit rotation e^{i phi} (complex); omega, alpha."""

    z: Complex
    dz: Complex
    ddz: Complex
    rot: Complex
    omega: Array
    alpha: Array

    def point(self, r: complex | Complex) -> tuple[Complex, Complex, Complex]:
        """Position, velocity and acceleration of a point r fixed in this frame."""
        arm = self.rot * r
        return self.z + arm, self.dz + 1j * self.omega * arm, self.ddz + (1j * self.alpha - self.omega**2) * arm

    def child(self, r: complex, rot: Complex, omega: Array, alpha: Array) -> _Frame:
        """Frame hinged at r in this one, turned by rot = e^{i angle} at (omega, alpha) relative to it."""
        z, dz, ddz = self.point(r)
        return _Frame(z, dz, ddz, self.rot * rot, self.omega + omega, self.alpha + alpha)

    def slider(self, r: complex | Complex, u: complex | Complex, dx: Array, ddx: Array) -> _Frame:
        """Frame translating along unit u (this frame's axes) at rate dx, now at r."""
        z, dz, ddz = self.point(r)
        u_world = self.rot * u
        dz = dz + u_world * dx
        ddz = ddz + 2j * self.omega * u_world * dx + u_world * ddx
        return _Frame(z, dz, ddz, self.rot, self.omega, self.alpha)


def _cross(a: Complex, b: Complex) -> Array:
    """Cross product (its z component) of in-plane vectors."""
    return (a.conj() * b).imag


def _wrench(frame: _Frame, body: PlanarInertia, gravity: float) -> tuple[Complex, Array]:
    """Planar Newton-Euler: force m (a_c - g) [N] and moment about {W}'s origin [N m] on a link."""
    p, _, a = frame.point(body.com)
    force = body.mass * (a + 1j * gravity)
    return force, body.inertia * frame.alpha + _cross(p, force)


def _chain(
    model: PlanarModel,
    chain: ClosedChain,
    parent: _Frame,
    theta: Array,
    dtheta: Array,
    ddtheta: Array,
) -> tuple[_Frame, _Frame, _Frame, tuple[Array, Array, Array]]:
    """Boom, cylinder and rod frames of one chain, and the actuator's (x, dx, ddx).

    The boom turns by theta - joint_offset relative to {Bc} (eq. thetas with theta = psi - q).
    The loop closes at the rod-end pivot {Tc} (seed eq. frames, const_m): with d = {Tc} - {Bc}
    = s e^{i psi}, the pin-to-pin length s = x + x0 and the cylinder angle psi are the polar
    coordinates of d, so with v_d, a_d its velocity and acceleration and e = d / s

        dx = Re(e* v_d),  omega = Im(e* v_d) / s,
        ddx = Re(e* a_d) + s omega^2,  alpha = (Im(e* a_d) - 2 dx omega) / s,

    which are eqs. qus_a, dq__ and 04 (x, dq1 = k2 dx, ddq1 = dk2 dx + k2 ddx) written for the
    triangle's side vector instead of its angles.
    """
    x0, Lc0 = model.x0[chain.name], model.Lc0[chain.name]
    turn = np.exp(1j * (chain.base_axis_angle - chain.joint_offset + theta))
    boom = parent.child(model.hinge[chain.name], turn, dtheta, ddtheta)
    pivot, dpivot, ddpivot = parent.point(model.pivot[chain.name])
    end, dend, ddend = boom.point(chain.L1 + 0j)
    d, v, a = end - pivot, dend - dpivot, ddend - ddpivot
    s = np.abs(d)
    e = d / s
    ev, ea = e.conj() * v, e.conj() * a
    dx = ev.real
    omega = ev.imag / s
    ddx = ea.real + s * omega**2
    alpha = (ea.imag - 2.0 * dx * omega) / s
    cylinder = _Frame(pivot, dpivot, ddpivot, e, omega, alpha)
    rod = cylinder.slider(np.asarray(Lc0 + s - x0, dtype=np.complex128), 1.0 + 0j, dx, ddx)
    return boom, cylinder, rod, (s - x0, dx, ddx)


def _actuator_force(
    chain: ClosedChain,
    boom: _Frame,
    cylinder: _Frame,
    s: Array,
    subtree: tuple[Complex, Array],
    pair: tuple[Complex, Array],
    rod_force: Complex,
) -> Array:
    """Pin force at {Tc} from the moment balances at {Bc} (pair) and {B1} (boom subtree); f = e.f_rod + P.e."""
    e = cylinder.rot
    arm = boom.rot * chain.L1
    pin_normal = -(pair[1] - _cross(cylinder.z, pair[0])) / s
    moment_hinge = subtree[1] - _cross(boom.z, subtree[0])
    pin_axial = (moment_hinge - pin_normal * _cross(arm, 1j * e)) / _cross(arm, e)
    return (e.conj() * rod_force).real + pin_axial


def planar_inverse_dynamics(
    crane: Crane, lengths: LinkLengths, position: Array, velocity: Array, acceleration: Array, tcp_force: Array
) -> tuple[Array, Array, Array, Array]:
    """Actuator forces, velocities, accelerations and strokes (each (T, 3)); inputs unchecked.

    ``tcp_force`` (T, 3) in {W} [N]; only its x, y components do work in the plane.
    """
    return planar_solve(crane, planar_model(crane, lengths), position, velocity, acceleration, tcp_force)


def planar_solve(
    crane: Crane, model: PlanarModel, position: Array, velocity: Array, acceleration: Array, tcp_force: Array
) -> tuple[Array, Array, Array, Array]:
    """:func:`planar_inverse_dynamics` on a planar model (one design, or a stack of designs per sample)."""
    T = position.shape[0]
    zero = np.zeros(T)
    origin = np.zeros(T, complex)
    base = _Frame(origin, origin, origin, np.ones(T, complex), zero, zero)
    lift = _chain(model, crane.lift, base, position[:, 0], velocity[:, 0], acceleration[:, 0])
    tilt = _chain(model, crane.tilt, lift[0], position[:, 1], velocity[:, 1], acceleration[:, 1])
    tilt_boom = tilt[0]
    slide = np.asarray(
        model.telescope_origin + model.telescope_axis * (crane.telescope.rod_offset + position[:, 2]),
        dtype=np.complex128,
    )
    rod = tilt_boom.slider(slide, model.telescope_axis, velocity[:, 2], acceleration[:, 2])

    g, L = crane.gravity, model.links
    wrench = {
        LIFT_BOOM: _wrench(lift[0], L[LIFT_BOOM], g),
        LIFT_CYLINDER: _wrench(lift[1], L[LIFT_CYLINDER], g),
        LIFT_ROD: _wrench(lift[2], L[LIFT_ROD], g),
        TILT_BOOM: _wrench(tilt_boom, L[TILT_BOOM], g),
        TILT_CYLINDER: _wrench(tilt[1], L[TILT_CYLINDER], g),
        TILT_ROD: _wrench(tilt[2], L[TILT_ROD], g),
    }
    f_rod, m_rod = _wrench(rod, L[TELESCOPE_ROD], g)
    external = tcp_force[:, 0] + 1j * tcp_force[:, 1]
    tcp_point, _, _ = rod.point(model.tcp)
    f_rod, m_rod = f_rod - external, m_rod - _cross(tcp_point, external)
    f_telescope = (np.conj(tilt_boom.rot * model.telescope_axis) * f_rod).real

    def add(*names: str) -> tuple[Complex, Array]:
        return sum(wrench[n][0] for n in names), sum(wrench[n][1] for n in names)  # type: ignore[return-value]

    tilt_sub = (wrench[TILT_BOOM][0] + f_rod, wrench[TILT_BOOM][1] + m_rod)
    s_tilt = model.x0[TILT] + tilt[3][0]
    f_tilt = _actuator_force(
        crane.tilt, tilt_boom, tilt[1], s_tilt, tilt_sub, add(TILT_CYLINDER, TILT_ROD), wrench[TILT_ROD][0]
    )
    tilt_all = add(LIFT_BOOM, TILT_CYLINDER, TILT_ROD)
    lift_sub = (tilt_all[0] + tilt_sub[0], tilt_all[1] + tilt_sub[1])
    s_lift = model.x0[LIFT] + lift[3][0]
    f_lift = _actuator_force(
        crane.lift, lift[0], lift[1], s_lift, lift_sub, add(LIFT_CYLINDER, LIFT_ROD), wrench[LIFT_ROD][0]
    )
    force = np.stack([f_lift, f_tilt, f_telescope], axis=1)
    states = [
        np.stack([lift[3][k], tilt[3][k], col[:, 2]], axis=1)
        for k, col in enumerate((position, velocity, acceleration))
    ]
    return force, states[1], states[2], states[0]

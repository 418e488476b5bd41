"""Planar kinematics of a machine tree, numpy only: loop closure, body motion and loop Jacobians.

In-plane vectors are complex numbers x + i y in the world. Every body's frame has the world
rotation Rz(theta) F, with F its rotation at zero coordinates (which holds any out-of-plane tilt
of the frame; revolute joints turn about the plane normal, prismatic ones slide in the plane) and
theta the sum of the revolute coordinates from the root. A point r fixed in the body lies at

    p = z + e^{i theta} (F r)_xy,   dp = dz + i omega (p - z),   ddp = ddz + (i alpha - omega^2)(p - z),

and a prismatic child at coordinate q, rate dq, along u = (F_parent R_joint e_x)_xy adds u dq to
its velocity and 2 i omega u dq + u ddq to its acceleration (Coriolis and slide acceleration).

Loop closure (positions, closed form; :mod:`hiab_sim.machine.dynamics.tree` names the bodies):

* triangle: d = end - base = s e^{i psi}; stroke x = s - x0, cylinder hinge angle psi - (angle of
  the base link's x axis);
* linkage: H is the intersection of the circles |H - J| = rocker_length, |H - K| =
  coupler_length on side ``pin_side`` of J -> K; the rocker points to H, the coupler from H to K,
  the actuator from its base pivot to H.

Rates: with C(q) = p_a - p_b = 0 at every loop pin and its Jacobian J = [J_i, J_d] (independent,
dependent coordinates), J_d dq_d = -J_i dq_i and J_d ddq_d = -(J_i ddq_i + dJ dq), where
J_i ddq_i + dJ dq is the pins' relative acceleration with ddq_d = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.tree import MachineTree, actuator_lengths

Complex = NDArray[np.complex128]


def _xy(v: Array) -> complex:
    return complex(float(v[0]), float(v[1]))


@dataclass(frozen=True)
class PlanarBody:
    """Constant planar data of a tree body (see the module docstring).

    ``fixed`` F (3, 3); ``origin`` joint origin in the parent's planar coordinates [m];
    ``axis`` unit slide direction there (prismatic); ``offset`` angle of F's x axis in the plane
    [rad]; ``mass`` [kg], ``com`` planar centre of mass, ``inertia_zz`` about it [kg m^2].
    """

    fixed: Array
    origin: complex
    axis: complex
    offset: float
    mass: float
    com: complex
    inertia_zz: float

    def point(self, r: Array) -> complex:
        """Planar coordinates (F r)_xy of a point r (3,) given in the body frame [m]."""
        return _xy(self.fixed @ np.asarray(r, dtype=float))


def planar_bodies(tree: MachineTree) -> tuple[PlanarBody, ...]:
    """Planar data of every body of the tree (parents first)."""
    out: list[PlanarBody] = []
    for body in tree.bodies:
        parent = np.eye(3) if body.parent < 0 else out[body.parent].fixed
        fixed = parent @ body.rotation
        if body.inertia is None:
            mass, com, izz = 0.0, 0j, 0.0
        else:
            inertia = fixed @ np.asarray(body.inertia.inertia) @ fixed.T
            mass, com, izz = body.inertia.mass, _xy(fixed @ np.asarray(body.inertia.com)), float(inertia[2, 2])
        axis = _xy(fixed[:, 0])
        out.append(
            PlanarBody(
                fixed=fixed,
                origin=_xy(parent @ body.position),
                axis=axis / abs(axis) if body.kind == "prismatic" else 0j,
                offset=float(np.arctan2(fixed[1, 0], fixed[0, 0])),
                mass=mass,
                com=com,
                inertia_zz=izz,
            )
        )
    return tuple(out)


@dataclass
class Frames:
    """Motion of every body frame over T samples (lists indexed by body, each (T,)).

    ``z``, ``dz``, ``ddz``: origin position, velocity, acceleration (complex) [m, m/s, m/s^2];
    ``theta``, ``omega``, ``alpha``: planar angle [rad], rate, acceleration of the frame;
    ``rot``: e^{i theta}.
    """

    z: list[Complex]
    dz: list[Complex]
    ddz: list[Complex]
    theta: list[Array]
    omega: list[Array]
    alpha: list[Array]
    rot: list[Complex]

    def position(self, b: int, r: complex | Complex) -> Complex:
        """Position of planar point r of body b."""
        return self.z[b] + self.rot[b] * r

    def point(self, b: int, r: complex | Complex) -> tuple[Complex, Complex, Complex]:
        """Position, velocity and acceleration of planar point r of body b."""
        arm = self.rot[b] * r
        w, a = self.omega[b], self.alpha[b]
        return self.z[b] + arm, self.dz[b] + 1j * w * arm, self.ddz[b] + (1j * a - w**2) * arm


def frames(
    tree: MachineTree, planar: tuple[PlanarBody, ...], q: Array, dq: Array | None = None, ddq: Array | None = None
) -> Frames:
    """Forward kinematics of all bodies for full coordinates q, dq, ddq (T, nbody); column b is body b's joint.

    Without ``dq`` and ``ddq`` only positions are computed (rates and accelerations are left zero).
    """
    T = q.shape[0]
    out = Frames([], [], [], [], [], [], [])
    if dq is None or ddq is None:
        return _positions(tree, planar, q, out)
    for b, body in enumerate(tree.bodies):
        p = planar[b]
        if body.parent < 0:
            zero = np.zeros(T)
            out.z.append(np.full(T, p.origin, dtype=complex))
            for series in (out.dz, out.ddz):
                series.append(np.zeros(T, dtype=complex))
            out.theta.append(zero)
            out.omega.append(zero)
            out.alpha.append(zero)
            out.rot.append(np.ones(T, dtype=complex))
            continue
        parent = body.parent
        if body.kind == "revolute":
            z, dz, ddz = out.point(parent, p.origin)
            theta, omega, alpha = (
                out.theta[parent] + q[:, b],
                out.omega[parent] + dq[:, b],
                out.alpha[parent] + ddq[:, b],
            )
            rot = out.rot[parent] * np.exp(1j * q[:, b])
        else:
            z, dz, ddz = out.point(parent, np.asarray(p.origin + p.axis * q[:, b], dtype=np.complex128))
            u = out.rot[parent] * p.axis
            dz = dz + u * dq[:, b]
            ddz = ddz + 2j * out.omega[parent] * u * dq[:, b] + u * ddq[:, b]
            theta, omega, alpha = out.theta[parent], out.omega[parent], out.alpha[parent]
            rot = out.rot[parent]
        out.z.append(z)
        out.dz.append(dz)
        out.ddz.append(ddz)
        out.theta.append(theta)
        out.omega.append(omega)
        out.alpha.append(alpha)
        out.rot.append(rot)
    return out


def _positions(tree: MachineTree, planar: tuple[PlanarBody, ...], q: Array, out: Frames) -> Frames:
    """Body frame positions and rotations only (see :func:`frames`)."""
    zero, zero_c = np.zeros(q.shape[0]), np.zeros(q.shape[0], dtype=complex)
    for b, body in enumerate(tree.bodies):
        p = planar[b]
        if body.parent < 0:
            z, theta, rot = np.full(q.shape[0], p.origin, dtype=complex), zero, np.ones(q.shape[0], dtype=complex)
        elif body.kind == "revolute":
            z = out.position(body.parent, p.origin)
            theta, rot = out.theta[body.parent] + q[:, b], out.rot[body.parent] * np.exp(1j * q[:, b])
        else:
            z = out.position(body.parent, np.asarray(p.origin + p.axis * q[:, b], dtype=np.complex128))
            theta, rot = out.theta[body.parent], out.rot[body.parent]
        out.z.append(z)
        out.theta.append(theta)
        out.rot.append(rot)
        for series in (out.dz, out.ddz):
            series.append(zero_c)
        out.omega.append(zero)
        out.alpha.append(zero)
    return out


def _angle(frames_: Frames, planar: tuple[PlanarBody, ...], b: int) -> Array:
    """World angle of body b's x axis [rad] (for a planar frame)."""
    return frames_.theta[b] + planar[b].offset


def close_loops(tree: MachineTree, planar: tuple[PlanarBody, ...], q: Array) -> Array:
    """Full coordinates (T, nbody) with the loops closed for independent positions q (T, n_joints).

    Raises:
        InvalidInputError: a four-bar that cannot close (field ``<chain>.linkage``).

    """
    T = q.shape[0]
    full = np.zeros((T, len(tree.bodies)))
    full[:, list(tree.independent)] = q
    fk = frames(tree, planar, full)  # chain bodies (still at 0) do not move the machine links

    def at(link: int, r: np.ndarray) -> Complex:
        return fk.position(link, planar[link].point(r))

    for chain in tree.machine.chains:
        if chain.kind == "direct":
            continue
        cyl = tree.index(f"{chain.name}.cylinder")
        rod = cyl + 1
        base = at(tree.bodies[cyl].parent, tree.bodies[cyl].position)
        if chain.kind == "triangle":
            loop = next(p for p in tree.loops if p.body_a == rod)
            end = at(loop.body_b, loop.point_b)
        else:
            rocker = cyl + 2
            linkage = chain.linkage
            if linkage is None:
                raise AssertionError("a linkage chain carries its four-bar")
            j = at(tree.bodies[rocker].parent, tree.bodies[rocker].position)
            far = next(p for p in tree.loops if p.body_a == rocker + 1)
            k = at(far.body_b, far.point_b)
            span = np.abs(k - j)
            r1, r2 = linkage.rocker_length, linkage.coupler_length
            along = (span**2 + r1**2 - r2**2) / (2.0 * span)
            height2 = r1**2 - along**2
            if np.any(height2 < 0.0):
                raise InvalidInputError(
                    f"chains.{chain.name}.linkage", f"|K - J| = {float(span[np.argmax(height2 < 0)]):.6g} m",
                    f"must lie in [{abs(r1 - r2):.6g}, {r1 + r2:.6g}] for the four-bar to close", "m",
                )  # fmt: skip
            e = (k - j) / span
            end = j + e * (along + 1j * linkage.pin_side * np.sqrt(height2))
            psi_rocker = np.angle(end - j)
            full[:, rocker] = _wrap(psi_rocker - _angle(fk, planar, tree.bodies[rocker].parent))
            full[:, rocker + 1] = _wrap(np.angle(k - end) - psi_rocker)
        d = end - base
        full[:, cyl] = _wrap(np.angle(d) - _angle(fk, planar, tree.bodies[cyl].parent))
        full[:, rod] = np.abs(d) - sum(actuator_lengths(chain))
    return full


def _wrap(angle: Array) -> Array:
    return np.angle(np.exp(1j * angle))


def loop_points(
    tree: MachineTree, planar: tuple[PlanarBody, ...], fk: Frames
) -> list[tuple[Complex, Complex, Complex]]:
    """Per loop pin: relative position, velocity and acceleration p_a - p_b (complex, (T,))."""
    out = []
    for loop in tree.loops:
        a = fk.point(loop.body_a, planar[loop.body_a].point(loop.point_a))
        b = fk.point(loop.body_b, planar[loop.body_b].point(loop.point_b))
        out.append((a[0] - b[0], a[1] - b[1], a[2] - b[2]))
    return out


def point_jacobian(tree: MachineTree, planar: tuple[PlanarBody, ...], fk: Frames, b: int, r: complex) -> Complex:
    """Jacobian dp/dq (T, nbody) of point r of body b (complex): i (p - z_j) per revolute ancestor j, u_j per slide."""
    T = fk.z[0].shape[0]
    p = fk.position(b, r)
    jac = np.zeros((T, len(tree.bodies)), dtype=complex)
    j = b
    while tree.bodies[j].parent >= 0:
        body = tree.bodies[j]
        if body.kind == "revolute":
            jac[:, j] = 1j * (p - fk.z[j])
        else:
            jac[:, j] = fk.rot[body.parent] * planar[j].axis
        j = body.parent
    return jac


def loop_jacobian(tree: MachineTree, planar: tuple[PlanarBody, ...], fk: Frames) -> Array:
    """Jacobian (T, 2 n_loops, nbody) of the in-plane loop residuals p_a - p_b (rows x, y per pin)."""
    rows = []
    for loop in tree.loops:
        jac = point_jacobian(tree, planar, fk, loop.body_a, planar[loop.body_a].point(loop.point_a))
        jac = jac - point_jacobian(tree, planar, fk, loop.body_b, planar[loop.body_b].point(loop.point_b))
        rows.extend([jac.real, jac.imag])
    return np.stack(rows, axis=1)


def loop_state(
    tree: MachineTree, planar: tuple[PlanarBody, ...], q: Array, dq: Array, ddq: Array
) -> tuple[Array, Array, Array]:
    """Loop-consistent full coordinates, rates and accelerations (T, nbody) from independent samples (T, n)."""
    qf = close_loops(tree, planar, q)
    T, n = qf.shape
    dqf = np.zeros((T, n))
    ddqf = np.zeros((T, n))
    ind, dep = list(tree.independent), list(tree.dependent)
    dqf[:, ind] = dq
    ddqf[:, ind] = ddq
    if not dep:
        return qf, dqf, ddqf
    jac = loop_jacobian(tree, planar, frames(tree, planar, qf))
    jd = jac[:, :, dep]
    dqf[:, dep] = np.linalg.solve(jd, -np.einsum("tri,ti->tr", jac[:, :, ind], dq)[..., None])[..., 0]
    bias = loop_points(tree, planar, frames(tree, planar, qf, dqf, ddqf))  # ddq_d = 0 here
    rel = np.stack([c for _, _, a in bias for c in (a.real, a.imag)], axis=1)
    ddqf[:, dep] = np.linalg.solve(jd, -rel[..., None])[..., 0]
    return qf, dqf, ddqf

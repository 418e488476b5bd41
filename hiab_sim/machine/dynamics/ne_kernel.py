"""The Newton-Euler solve of :mod:`hiab_sim.machine.dynamics.newton_euler`, vectorised over designs and samples.

Arrays are body-major: (nbody, D, T) for D designs and T samples (or pins, chains first), so
that a body's row is contiguous; the numbers of each design
(:class:`~hiab_sim.machine.dynamics.ne_layout.NeConstants`, (n, D)) broadcast over its samples.
No Python loop runs over samples or designs; loops run over bodies and pin-force levels
(:mod:`hiab_sim.machine.dynamics.ne_layout`), and no matrix product or angle is needed.

1. The machine's links, base to tip (eqs. of :mod:`hiab_sim.machine.dynamics.planar`): with
   w = e^{i theta_p} c the joint offset c = origin + u q in the world,

       z = z_p + w,   dz = dz_p + i omega_p w + u dq,
       ddz = ddz_p + (i alpha_p - omega_p^2) w + 2 i omega_p u dq + u ddq,

   e^{i theta} = e^{i theta_p} e^{i q} across a hinge (one complex exponential per hinge).
2. Loop closure in closed form, chains of a kind at once: a four-bar's pin H on the circles about
   J and K, its rates from v_K - v_J = i omega_r (H - J) + i omega_c (K - H) (dotted with K - H and
   H - J); every actuator as the triangle base -> end, d = s e (|e| = 1):

       dx = Re(e* v_d),  omega = Im(e* v_d) / s,  ddx = Re(e* a_d) + s omega^2,
       alpha = (Im(e* a_d) - 2 dx omega) / s,

   the exact solution of J_d dq_d = -J_i dq_i and its derivative (``planar``'s docstring). The
   chain bodies' frames follow directly: e.g. the cylinder turns with e, its origin is the pivot.
3. Per body the Newton-Euler force and moment about O, summed tip to base over subtrees, and the
   hinge equations M_O - o_b x F = 0 solved for the loop-pin forces lambda block by block (a 2 x 2
   block: cross(d_1, lambda) = a_1, cross(d_2, lambda) = a_2 gives
   lambda = (a_1 d_2 - a_2 d_1) / cross(d_1, d_2)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.ne_layout import NeConstants, NeLayout

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]
Index = NDArray[np.intp]
Motion = tuple[Complex, Complex, Complex]


def cross(a: Complex, b: Complex) -> Array:
    """The z component of the cross product of in-plane vectors (complex), a_x b_y - a_y b_x."""
    out: Array = a.real * b.imag - a.imag * b.real
    return out


def dot(a: Complex, b: Complex) -> Array:
    """The dot product of in-plane vectors (complex)."""
    out: Array = a.real * b.real + a.imag * b.imag
    return out


@dataclass
class NeFrames:
    """Motion of every body frame, (nbody, D, T): e^{i theta}, origins (complex) [m], rates [rad/s, rad/s^2].

    ``spin`` = i omega and ``turn`` = i alpha - omega^2 (the factors of a point's velocity and
    acceleration relative to the origin, kept for the many points of a body).
    """

    rot: Complex
    z: Complex
    dz: Complex
    ddz: Complex
    omega: Array
    alpha: Array
    spin: Complex
    turn: Complex

    def points(self, bodies: Index | int, r: Complex) -> Motion:
        """Position, velocity, acceleration of planar points r ((k, D, 1) or broadcastable) of ``bodies``."""
        arm = self.rot[bodies] * r
        return self.z[bodies] + arm, self.dz[bodies] + self.spin[bodies] * arm, self.ddz[bodies] + self.turn[bodies] * arm

    def orient(self, bodies: Index | int, rot: Complex, omega: Array, alpha: Array) -> None:
        """Set the rotation and rates of ``bodies`` (and their spin and turn)."""
        self.rot[bodies], self.omega[bodies], self.alpha[bodies] = rot, omega, alpha
        self.spin[bodies] = 1j * omega
        self.turn[bodies] = 1j * alpha - omega * omega

    def place(self, bodies: Index | int, motion: Motion) -> None:
        """Set the origin's position, velocity and acceleration of ``bodies``."""
        self.z[bodies], self.dz[bodies], self.ddz[bodies] = motion


def new_frames(shape: tuple[int, ...], origin: Complex) -> NeFrames:
    """Frames to be filled, the root's set: at ``origin`` (D, 1) [m], unrotated, at rest."""
    real = [np.empty(shape) for _ in range(2)]
    cplx = [np.empty(shape, dtype=complex) for _ in range(6)]
    for array in (*real, *cplx):
        array[0] = 0.0
    cplx[0][0] = 1.0
    cplx[1][0] = origin
    return NeFrames(cplx[0], cplx[1], cplx[2], cplx[3], real[0], real[1], cplx[4], cplx[5])


def forward(layout: NeLayout, c: NeConstants, fr: NeFrames, bodies: range, q: Array, dq: Array, ddq: Array) -> None:
    """Frames of ``bodies`` (parents first, each parent's frame known) from full coordinates (step 1)."""
    hinges = [b for b in bodies if layout.revolute[b]]
    turns = dict(zip(hinges, np.exp(1j * q[hinges]), strict=True))
    for b in bodies:
        p = layout.parent[b]
        if b in turns:
            fr.orient(b, fr.rot[p] * turns[b], fr.omega[p] + dq[b], fr.alpha[p] + ddq[b])
            w = fr.rot[p] * c.origin[b][:, None]
            fr.place(b, (fr.z[p] + w, fr.dz[p] + fr.spin[p] * w, fr.ddz[p] + fr.turn[p] * w))
            continue
        for series in (fr.rot, fr.omega, fr.alpha, fr.spin, fr.turn):  # a slide turns with its parent
            series[b] = series[p]
        u = fr.rot[p] * layout.axis[b]
        w = fr.rot[p] * c.origin[b][:, None] + u * q[b]
        spin_u = fr.spin[p] * u
        fr.place(
            b,
            (fr.z[p] + w, fr.dz[p] + fr.spin[p] * w + u * dq[b], fr.ddz[p] + fr.turn[p] * w + (2.0 * dq[b]) * spin_u + u * ddq[b]),
        )


def close_chains(
    layout: NeLayout, c: NeConstants, fr: NeFrames, q: Array, dq: Array, ddq: Array, angles: bool = False
) -> None:
    """Chain bodies' frames, and the rods' (and with ``angles`` every chain joint's) coordinates (step 2).

    The links' frames must be filled. Chain hinge coordinates are written only with ``angles``
    (nothing else needs them).

    Raises:
        InvalidInputError: a four-bar that cannot close (field ``chains.<chain>.linkage``).

    """
    g = layout.groups
    origin = c.origin[:, :, None]
    cyl, rod, base, x0 = g.tri_cyl, g.tri_rod, g.tri_base, c.x0[g.tri_chain][:, :, None]
    end = fr.points(g.tri_end, c.point_b[g.tri_loop][:, :, None])
    if len(g.bar_chain):
        H = _four_bar(layout, fr, origin, c, q, dq, ddq, angles)
        end = (np.concatenate([e, h]) for e, h in zip(end, H, strict=True))  # type: ignore[assignment]
        cyl, rod, base = np.concatenate([cyl, g.bar_cyl]), np.concatenate([rod, g.bar_rod]), np.concatenate([base, g.bar_base])
        x0 = np.concatenate([x0, c.x0[g.bar_chain][:, :, None]])
    if not len(cyl):
        return
    pivot = fr.points(base, origin[cyl])
    d, v, a = (e - p for e, p in zip(end, pivot, strict=True))
    s = np.abs(d)
    e = d / s
    ev, ea = e.conj() * v, e.conj() * a
    dx = ev.real
    omega = ev.imag / s
    ddx = ea.real + s * omega * omega
    alpha = (ea.imag - 2.0 * dx * omega) / s
    fr.orient(cyl, e * layout.unturn[cyl][:, None, None], omega, alpha)
    fr.place(cyl, pivot)
    fr.orient(rod, fr.rot[cyl], omega, alpha)
    x = s - x0
    u = fr.rot[cyl] * layout.axis[rod][:, None, None]
    w = fr.rot[cyl] * origin[rod] + u * x
    spin_u = fr.spin[cyl] * u
    fr.place(rod, (pivot[0] + w, pivot[1] + fr.spin[cyl] * w + u * dx, pivot[2] + fr.turn[cyl] * w + 2.0 * dx * spin_u + u * ddx))
    q[rod], dq[rod], ddq[rod] = x, dx, ddx
    if angles:
        q[cyl] = np.angle(fr.rot[cyl] * fr.rot[base].conj())
        dq[cyl], ddq[cyl] = omega - fr.omega[base], alpha - fr.alpha[base]


def _four_bar(
    layout: NeLayout, fr: NeFrames, origin: Complex, c: NeConstants, q: Array, dq: Array, ddq: Array, angles: bool
) -> Motion:
    """Rocker and coupler frames (and coordinates); return the rod pin H's position, velocity, acceleration."""
    g = layout.groups
    J = fr.points(g.bar_j, origin[g.bar_rocker])
    K = fr.points(g.bar_k, c.point_b[g.bar_loop][:, :, None])
    r1, r2, side = (x[:, None, None] for x in (g.bar_r1, g.bar_r2, g.bar_side))
    span = np.abs(K[0] - J[0])
    along = (span * span + r1 * r1 - r2 * r2) / (2.0 * span)
    height2 = r1 * r1 - along * along
    if np.any(height2 < 0.0):
        k = int(np.argmax(np.any(height2 < 0.0, axis=(1, 2))))
        raise InvalidInputError(
            f"chains.{g.bar_names[k]}.linkage", f"|K - J| = {float(span[k][height2[k] < 0.0][0]):.6g} m",
            f"must lie in [{abs(g.bar_r1[k] - g.bar_r2[k]):.6g}, {g.bar_r1[k] + g.bar_r2[k]:.6g}] for the four-bar to close",
            "m",
        )  # fmt: skip
    H = J[0] + (K[0] - J[0]) / span * (along + 1j * side * np.sqrt(height2))
    arm, reach = H - J[0], K[0] - H  # rocker J -> H, coupler H -> K
    v, a = K[1] - J[1], K[2] - J[2]
    turn = cross(arm, reach)
    w_r, w_c = dot(reach, v) / turn, -dot(arm, v) / turn
    rest = a + w_r * w_r * arm + w_c * w_c * reach
    a_r, a_c = dot(reach, rest) / turn, -dot(arm, rest) / turn
    rocker, coupler, link = g.bar_rocker, g.bar_coupler, g.bar_j
    H_motion = (H, J[1] + 1j * w_r * arm, J[2] + (1j * a_r - w_r * w_r) * arm)
    fr.orient(rocker, arm / r1 * layout.unturn[rocker][:, None, None], w_r, a_r)
    fr.place(rocker, J)
    fr.orient(coupler, reach / r2 * layout.unturn[coupler][:, None, None], w_c, a_c)
    fr.place(coupler, H_motion)
    if angles:
        q[rocker] = np.angle(fr.rot[rocker] * fr.rot[link].conj())
        dq[rocker], ddq[rocker] = w_r - fr.omega[link], a_r - fr.alpha[link]
        q[coupler] = np.angle(reach * arm.conj())
        dq[coupler], ddq[coupler] = w_c - w_r, a_c - a_r
    return H_motion


def full_state(
    layout: NeLayout, c: NeConstants, q: Array, dq: Array, ddq: Array, angles: bool = False
) -> tuple[Array, Array, Array, NeFrames]:
    """Full coordinates, rates, accelerations (nbody, D, T) and every body's frame.

    ``q``, ``dq``, ``ddq``: the independent joints (n_joints, 1 or D, T), unchecked. Chain hinge
    entries are filled only with ``angles`` (the rods' always).
    """
    shape = (layout.n_bodies, max(c.designs, q.shape[1]), q.shape[2])
    full = [np.zeros(shape) for _ in range(3)]
    for array, given in zip(full, (q, dq, ddq), strict=True):
        array[layout.independent] = given
    fr = new_frames(shape, c.origin[0][:, None])
    forward(layout, c, fr, range(1, layout.n_links), *full)
    close_chains(layout, c, fr, *full, angles=angles)
    return full[0], full[1], full[2], fr


def frames_of_full(layout: NeLayout, c: NeConstants, q: Array, dq: Array, ddq: Array) -> NeFrames:
    """Every body's frame for full coordinates (nbody, D, T) as they are (no loop closure)."""
    fr = new_frames(q.shape, c.origin[0][:, None])
    forward(layout, c, fr, range(1, layout.n_bodies), q, dq, ddq)
    return fr


def joint_forces(
    layout: NeLayout, c: NeConstants, fr: NeFrames, external: Complex | complex | None
) -> tuple[Complex, Complex]:
    """Force each joint transmits from parent to body (nbody, D, T) and the loop-pin forces lambda (n_pins, D, T).

    ``external``: the TCP force of the environment (complex) [N], (T,), a scalar or None (step 3).
    """
    mb = layout.massive
    arm = fr.rot[mb] * c.com[mb][:, :, None]
    net = c.mass[mb][:, :, None] * (fr.ddz[mb] + fr.turn[mb] * arm + 1j * layout.tree.gravity)
    force = np.zeros(fr.z.shape, dtype=complex)
    moment = np.zeros(fr.omega.shape)
    force[mb] = net
    moment[mb] = c.izz[mb][:, :, None] * fr.alpha[mb] + cross(fr.z[mb] + arm, net)
    if external is not None:
        tb = layout.tree.tcp_body
        tcp = fr.z[tb] + fr.rot[tb] * layout.tcp_point
        force[tb] -= external
        moment[tb] -= cross(tcp, np.asarray(external, dtype=complex))
    for b in range(layout.n_bodies - 1, 1, -1):  # parents precede children: add each subtree into its parent's
        p = layout.parent[b]
        if p > 0:
            force[p] += force[b]
            moment[p] += moment[b]
    s = layout.system
    lam = np.zeros((len(layout.tree.loops), *fr.z.shape[1:]), dtype=complex)
    if len(s.pin):
        side_point = np.concatenate([c.point_a, c.point_b])[s.pin + len(layout.tree.loops) * s.side][:, :, None]
        d = fr.z[s.side_body] - fr.z[s.hinge[s.row]] + fr.rot[s.side_body] * side_point
        rhs = cross(fr.z[s.hinge], force[s.hinge]) - moment[s.hinge]
        for pins, e1, e2, earlier, feed in s.levels:
            r1, r2 = rhs[s.row[e1]], rhs[s.row[e2]]
            if len(earlier):
                known = s.sign[earlier][:, None, None] * cross(d[earlier], lam[s.pin[earlier]])
                r1 = r1 - np.tensordot(feed[:, : len(pins)], known, axes=(0, 0))
                r2 = r2 - np.tensordot(feed[:, len(pins) :], known, axes=(0, 0))
            d1, d2 = d[e1], d[e2]
            lam[pins] = (r1 * s.sign[e1][:, None, None] * d2 - r2 * s.sign[e2][:, None, None] * d1) / cross(d1, d2)
        if s.dense is not None:
            _dense_pins(layout, d, rhs, lam)
    for k, b, sign in s.transmit:
        if sign > 0.0:
            force[b] += lam[k]
        else:
            force[b] -= lam[k]
    return force, lam


def _dense_pins(layout: NeLayout, d: Complex, rhs: Array, lam: Complex) -> None:
    """The pins no 2 x 2 block determines, in one dense solve (real unknowns lambda_x, lambda_y per pin)."""
    s = layout.system
    if s.dense is None:
        return
    pins, rows = s.dense
    col = {int(k): i for i, k in enumerate(pins)}
    at = {int(r): i for i, r in enumerate(rows)}
    matrix = np.zeros((*rhs.shape[1:], 2 * len(pins), 2 * len(pins)))
    right = np.moveaxis(rhs[rows], 0, -1).copy()
    for e in range(len(s.pin)):
        r, k = int(s.row[e]), int(s.pin[e])
        if r not in at:
            continue
        if k in col:
            matrix[..., at[r], 2 * col[k]] += -s.sign[e] * d[e].imag
            matrix[..., at[r], 2 * col[k] + 1] += s.sign[e] * d[e].real
        else:
            right[..., at[r]] -= s.sign[e] * cross(d[e], lam[k])
    x = np.moveaxis(np.linalg.solve(matrix, right[..., None])[..., 0], -1, 0)
    lam[pins] = x[0::2] + 1j * x[1::2]


def actuator_forces(layout: NeLayout, fr: NeFrames, transmitted: Complex) -> Array:
    """Axial force f_x of each actuated slide (n_chains, D, T) [N]: u . F of its joint's transmitted force."""
    u = fr.rot[layout.act_parent] * layout.axis[layout.actuated][:, None, None]
    return dot(u, transmitted[layout.actuated])


def pin_arrays(layout: NeLayout, fr: NeFrames, transmitted: Complex, lam: Complex) -> tuple[Array, Array]:
    """World (D, T, P, 2) and body-frame (D, T, P, 3) forces of the joints and pins of :func:`pin_layout` [N].

    In the frame Rz(theta) F of the body acted on: [Re, Im, 0](e^{-i theta} f) F (the row-vector form).
    """
    n = layout.n_bodies - 1
    world = np.empty((*transmitted.shape[1:], n + lam.shape[0]), dtype=complex)
    world[..., :n] = np.moveaxis(transmitted[1:], 0, -1)
    world[..., n:] = np.moveaxis(lam, 0, -1)
    turned = world * np.moveaxis(fr.rot[layout.pins_on], 0, -1).conj()
    fixed = layout.fixed[layout.pins_on]
    local = turned.real[..., None] * fixed[:, 0, :] + turned.imag[..., None] * fixed[:, 1, :]
    return world.view(np.float64).reshape(*world.shape, 2), local

"""The motion half of the Newton-Euler solve: every body's frame, vectorised over designs and samples.

Arrays (nbody, D, T) for D designs and T samples live in a
:class:`~hiab_sim.machine.dynamics.ne_workspace.Workspace` and are written in place; each
design's numbers come shaped to broadcast over its samples
(:class:`~hiab_sim.machine.dynamics.ne_workspace.Prepared`). No Python loop runs over samples or
designs, only over bodies.

1. The machine's links, base to tip (eqs. of :mod:`hiab_sim.machine.dynamics.planar`): with
   w = e^{i theta_p} c the joint offset c = origin + u q turned into the world,

       z = z_p + w,   dz = dz_p + i omega_p w + u dq,
       ddz = ddz_p + (i alpha_p - omega_p^2) w + 2 i omega_p u dq + u ddq,

   e^{i theta} = e^{i theta_p} e^{i q} across a hinge (one complex exponential per hinge).
2. Loop closure in closed form, chains of a kind at once: a four-bar's pin H on the circles about
   J and K, its rates from v_K - v_J = i omega_r (H - J) + i omega_c (K - H) (dotted with K - H and
   H - J); every actuator as the triangle base -> end, d = s e (|e| = 1):

       dx = Re(e* v_d),  omega = Im(e* v_d) / s,  ddx = Re(e* a_d) + s omega^2,
       alpha = (Im(e* a_d) - 2 dx omega) / s,

   the exact solution of J_d dq_d = -J_i dq_i and its derivative (``planar``'s docstring). The
   chain bodies' frames follow directly: the cylinder turns with e and sits on its base pivot.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.machine.dynamics.ne_four_bar import four_bars
from hiab_sim.machine.dynamics.ne_layout import NeLayout
from hiab_sim.machine.dynamics.ne_workspace import Prepared, Workspace, workspace

Complex = NDArray[np.complex128]


def cross(a: Complex, b: Complex) -> Array:
    """The z component of the cross product of in-plane vectors (complex), a_x b_y - a_y b_x."""
    out: Array = a.real * b.imag - a.imag * b.real
    return out


def forward(ws: Workspace, pc: Prepared, bodies: range) -> None:
    """Frames of ``bodies`` (parents first, each parent's frame known) from ``ws.q``, ``dq``, ``ddq`` (step 1)."""
    layout = ws.layout
    q, dq, ddq, motion, factor = ws.q, ws.dq, ws.ddq, ws.motion, ws.factor
    w, u, tmp = ws.c("forward", 3)
    moved = ws.c("forward motion", 3)
    square = ws.r("forward")
    for b in bodies:
        p = layout.parent[b]
        origin = pc.origin[b]
        if layout.revolute[b]:
            np.multiply(q[b], 1j, out=tmp)
            if p == 0:  # on the root (unrotated, at rest): the hinge stays at z_0 + origin
                np.exp(tmp, out=ws.rot[b])
                ws.omega[b], ws.alpha[b] = dq[b], ddq[b]
            else:
                np.exp(tmp, out=tmp)
                np.multiply(ws.rot[p], tmp, out=ws.rot[b])
                np.add(ws.omega[p], dq[b], out=ws.omega[b])
                np.add(ws.alpha[p], ddq[b], out=ws.alpha[b])
            np.multiply(ws.omega[b], 1j, out=factor[1, b])
            np.multiply(ws.alpha[b], 1j, out=factor[2, b])
            np.multiply(ws.omega[b], ws.omega[b], out=square)
            factor[2, b] -= square
            if p == 0:
                np.add(motion[0, 0], origin, out=motion[0, b])
                motion[1:, b] = 0.0
                continue
            np.multiply(ws.rot[p], origin, out=w)
            np.multiply(factor[:, p], w, out=moved)
            np.add(motion[:, p], moved, out=motion[:, b])
            continue
        for series in (ws.rot, ws.omega, ws.alpha):  # a slide turns with its parent
            series[b] = series[p]
        factor[1:, b] = factor[1:, p]
        np.multiply(ws.rot[p], layout.axis[b], out=u)
        np.multiply(ws.rot[p], origin, out=w)
        np.multiply(u, q[b], out=tmp)
        w += tmp
        np.multiply(factor[:, p], w, out=moved)
        np.add(motion[:, p], moved, out=motion[:, b])
        np.multiply(u, dq[b], out=tmp)
        motion[1, b] += tmp  # u dq
        np.multiply(factor[1, p], dq[b], out=tmp)
        tmp *= 2.0
        tmp += ddq[b]
        tmp *= u
        motion[2, b] += tmp  # 2 i omega_p u dq + u ddq


def close_chains(ws: Workspace, pc: Prepared, angles: bool = False) -> None:
    """Chain bodies' frames and the rods' coordinates (with ``angles`` every chain joint's) (step 2).

    The links' frames must be filled. Chain hinge coordinates are written only with ``angles``
    (nothing else needs them).

    Raises:
        InvalidInputError: a four-bar that cannot close (field ``chains.<chain>.linkage``).

    """
    g = ws.layout.groups
    n_tri, k = len(g.tri_chain), len(pc.cyl)
    if k == 0:
        return
    cyl, rod, base = pc.cyl, pc.rod, pc.base
    end, pivot, spare = ws.c("end", 3, k), ws.c("pivot", 3, k), ws.c("spare", 3, k)
    e, arm, moved, turning = ws.c("e", k), ws.c("lever arm", k), ws.c("rod motion", 3, k), ws.c("turning", 3, k)
    ws.points(g.tri_end, pc.tri_end, end[:, :n_tri], (arm[:n_tri], spare[:, :n_tri]))
    if k > n_tri:
        end[:, n_tri:] = four_bars(ws, pc, angles)
    ws.points(base, pc.cyl_origin, pivot, (arm, spare))
    end -= pivot  # d, v_d, a_d
    s, inv, omega, alpha, ddx = ws.r("triangle", 5, k)
    np.abs(end[0], out=s)
    np.divide(1.0, s, out=inv)
    np.multiply(end[0], inv, out=e)  # e = d / s
    np.conjugate(e, out=arm)
    rel = spare[1:]
    np.multiply(arm, end[1:], out=rel)  # e* v_d, e* a_d
    dx, ev_imag, ea_real, ea_imag = rel[0].real, rel[0].imag, rel[1].real, rel[1].imag
    np.multiply(ev_imag, inv, out=omega)
    np.multiply(omega, omega, out=ddx)
    ddx *= s
    ddx += ea_real
    np.multiply(dx, omega, out=alpha)
    alpha *= -2.0
    alpha += ea_imag
    alpha *= inv
    e *= pc.unturn  # the cylinder's e^{i theta}
    ws.orient(pc.pair, e, omega, alpha, turning)  # the rod slides in the cylinder: it turns alike
    ws.motion[:, cyl] = pivot
    x = s
    x -= pc.x0  # stroke s - x0 (s is not needed any more)
    ws.q[rod], ws.dq[rod], ws.ddq[rod] = x, dx, ddx
    u, w = end[0], end[1]  # d, v_d are not needed any more either
    np.multiply(e, pc.rod_axis, out=u)
    np.multiply(e, pc.rod_origin, out=w)
    np.multiply(u, x, out=arm)
    w += arm
    np.multiply(turning, w, out=moved)
    moved += pivot
    np.multiply(u, dx, out=arm)
    moved[1] += arm  # u dx
    np.multiply(turning[1], dx, out=arm)
    arm *= 2.0
    arm += ddx
    arm *= u
    moved[2] += arm  # 2 i omega u dx + u ddx
    ws.motion[:, rod] = moved
    if angles:
        ws.q[cyl] = np.angle(ws.rot[cyl] * ws.rot[base].conj())
        ws.dq[cyl], ws.ddq[cyl] = omega - ws.omega[base], alpha - ws.alpha[base]


def full_state(
    layout: NeLayout, pc: Prepared, q: Array, dq: Array, ddq: Array, angles: bool = False, keep: bool = True
) -> Workspace:
    """Full coordinates, rates, accelerations (nbody, D, T) and every body's frame, in a workspace.

    ``q``, ``dq``, ``ddq``: the independent joints (n_joints, 1 or D, T), unchecked. Chain hinge
    entries are filled only with ``angles`` (the rods' always). ``keep``: take a kept workspace
    (its arrays are overwritten by the next call in this thread: copy what is returned).
    """
    D, T = max(pc.designs, q.shape[1]), q.shape[2]
    ws = workspace(layout, D, T) if keep else Workspace(layout, D, T)
    ind = layout.independent
    ws.q[ind], ws.dq[ind], ws.ddq[ind] = q, dq, ddq
    forward(ws, pc, range(1, layout.n_links))
    close_chains(ws, pc, angles=angles)
    return ws


def frames_of_full(layout: NeLayout, pc: Prepared, q: Array, dq: Array, ddq: Array) -> Workspace:
    """Every body's frame for full coordinates (nbody, D, T) as they are (no loop closure), in a new workspace."""
    ws = Workspace(layout, q.shape[1], q.shape[2])
    ws.q[...], ws.dq[...], ws.ddq[...] = q, dq, ddq
    forward(ws, pc, range(1, layout.n_bodies))
    return ws

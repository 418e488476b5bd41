"""The force half of the Newton-Euler solve: joint, pin and actuator forces from the frames of a workspace.

Step 3 of the solve (:mod:`hiab_sim.machine.dynamics.newton_euler` states the equations): per
body the Newton-Euler force and moment about O, (F, M_O) = (m (a_c - g), I_zz alpha + c x F),
summed tip to base over subtrees; the hinge equations M_O - o_b x F = 0 in the loop-pin forces
lambda, solved block by block in the order of
:class:`~hiab_sim.machine.dynamics.ne_layout.PinSystem` (a 2 x 2 block cross(d_1, lambda) = a_1,
cross(d_2, lambda) = a_2 gives lambda = (a_1 d_2 - a_2 d_1) / cross(d_1, d_2)); then each joint's
transmitted force is its subtree's plus the pin forces entering it. Arrays (n, D, T) as in
:mod:`hiab_sim.machine.dynamics.ne_kernel`, written in place in the workspace.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.machine.dynamics.ne_kernel import cross
from hiab_sim.machine.dynamics.ne_workspace import Prepared, Workspace

Complex = NDArray[np.complex128]


def _cross_into(out: Array, spare: Array, a: Complex, b: Complex) -> Array:
    """cross(a, b) = a_x b_y - a_y b_x into ``out`` (``spare``: scratch of its shape)."""
    np.multiply(a.real, b.imag, out=out)
    np.multiply(a.imag, b.real, out=spare)
    out -= spare
    return out


def joint_forces(ws: Workspace, pc: Prepared, external: Complex | complex | None) -> tuple[Complex, Complex]:
    """Force each joint transmits from parent to body (nbody, D, T) and the loop-pin forces lambda (n_pins, D, T).

    ``external``: the TCP force of the environment (complex) [N], (T,), a scalar or None. Both
    results are workspace arrays (overwritten by the next call).
    """
    layout = ws.layout
    mb, n = layout.massive, layout.n_bodies
    force, moment = ws.c("force", n), ws.r("moment", n)
    arm, at, net = ws.c("com arm", len(mb)), ws.c("com", len(mb)), ws.c("net", len(mb))
    ws.rot.take(mb, axis=0, out=arm, mode="clip")
    arm *= pc.com
    ws.motion[0].take(mb, axis=0, out=at, mode="clip")
    at += arm  # centre of mass
    ws.factor[2].take(mb, axis=0, out=net, mode="clip")
    net *= arm
    net += ws.motion[2].take(mb, axis=0, out=ws.c("com acceleration", len(mb)), mode="clip")
    net += 1j * layout.tree.gravity  # a_c - g, g = (0, -g)
    net *= pc.mass
    turning, spare = ws.r("turning", len(mb)), ws.r("spare", len(mb))
    _cross_into(turning, spare, at, net)
    ws.alpha.take(mb, axis=0, out=spare, mode="clip")
    spare *= pc.izz
    turning += spare
    force[layout.massless], moment[layout.massless] = 0.0, 0.0
    force[mb], moment[mb] = net, turning
    if external is not None:
        tb = layout.tree.tcp_body
        tcp, lever = ws.c("tcp", 1)[0], ws.r("tcp", 2)
        np.multiply(ws.rot[tb], layout.tcp_point, out=tcp)
        tcp += ws.motion[0, tb]
        force[tb] -= external
        ext = np.asarray(external)
        np.multiply(tcp.real, ext.imag, out=lever[0])
        np.multiply(tcp.imag, ext.real, out=lever[1])
        lever[0] -= lever[1]
        moment[tb] -= lever[0]  # tcp x F
    for b, p in layout.accumulate:  # tip to base: add each body's subtree into its parent's
        force[p] += force[b]
        moment[p] += moment[b]
    lam = ws.c("lambda", len(layout.tree.loops))
    s = layout.system
    if len(s.pin):
        _pin_forces(ws, pc, force, moment, lam)
    for k, b, sign in s.transmit:
        if sign > 0.0:
            force[b] += lam[k]
        else:
            force[b] -= lam[k]
    return force, lam


def _pin_forces(ws: Workspace, pc: Prepared, force: Complex, moment: Array, lam: Complex) -> None:
    """Lambda from the hinge equations, level by level (2 x 2 blocks), then the dense rest."""
    s = ws.layout.system
    z = ws.motion[0]
    n_entries, n_hinges = len(s.pin), len(s.hinge)
    d, tmp = ws.c("d", n_entries), ws.c("d-spare", n_entries)
    ws.rot.take(s.side_body, axis=0, out=d, mode="clip")
    d *= pc.side_point
    z.take(s.side_body, axis=0, out=tmp, mode="clip")
    d += tmp
    z.take(s.hinge[s.row], axis=0, out=tmp, mode="clip")
    d -= tmp  # arm from the hinge to the pin
    at, pull = ws.c("hinge-z", n_hinges), ws.c("hinge-f", n_hinges)
    rhs, spare = ws.r("rhs", n_hinges), ws.r("rhs-spare", n_hinges)
    z.take(s.hinge, axis=0, out=at, mode="clip")
    force.take(s.hinge, axis=0, out=pull, mode="clip")
    _cross_into(rhs, spare, at, pull)
    moment.take(s.hinge, axis=0, out=spare, mode="clip")
    rhs -= spare  # o_b x F - M_O
    for level, ((pins, e1, e2, earlier, feed), (sign1, sign2)) in enumerate(zip(s.levels, pc.signs, strict=True)):
        k = len(pins)
        r1, r2, den, den_spare = ws.r(f"level-{level}", 4, k)
        d1, d2, num, num_spare = ws.c(f"level-{level}", 4, k)
        rhs.take(s.row[e1], axis=0, out=r1, mode="clip")
        rhs.take(s.row[e2], axis=0, out=r2, mode="clip")
        if len(earlier):
            known = s.sign[earlier][:, None, None] * cross(d[earlier], lam[s.pin[earlier]])
            r1 -= np.tensordot(feed[:, :k], known, axes=(0, 0))
            r2 -= np.tensordot(feed[:, k:], known, axes=(0, 0))
        r1 *= sign1
        r2 *= sign2
        d.take(e1, axis=0, out=d1, mode="clip")
        d.take(e2, axis=0, out=d2, mode="clip")
        np.multiply(d2, r1, out=num)
        np.multiply(d1, r2, out=num_spare)
        num -= num_spare
        _cross_into(den, den_spare, d1, d2)
        np.divide(1.0, den, out=den)
        num *= den
        lam[pins] = num
    if s.dense is not None:
        _dense_pins(ws, d, rhs, lam)


def _dense_pins(ws: Workspace, d: Complex, rhs: Array, lam: Complex) -> None:
    """The pins no 2 x 2 block determines, in one dense solve (real unknowns lambda_x, lambda_y per pin)."""
    s = ws.layout.system
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


def actuator_forces(ws: Workspace, pc: Prepared, transmitted: Complex) -> Array:
    """Axial force f_x (n_chains, D, T) [N] of each actuated slide: u . F of its joint's force (a workspace array)."""
    layout = ws.layout
    n = len(layout.actuated)
    u, pull = ws.c("axis", n), ws.c("pull", n)
    ws.rot.take(layout.act_parent, out=u, axis=0, mode="clip")
    u *= pc.act_axis
    transmitted.take(layout.actuated, out=pull, axis=0, mode="clip")
    out, spare = ws.r("actuator force", n), ws.r("axis", n)
    np.multiply(u.real, pull.real, out=out)
    np.multiply(u.imag, pull.imag, out=spare)
    out += spare
    return out


def pin_arrays(ws: Workspace, transmitted: Complex, lam: Complex) -> tuple[Array, Array]:
    """World (D, T, P, 2) and body-frame (D, T, P, 3) forces of the joints and pins of :func:`pin_layout` [N].

    In the frame Rz(theta) F of the body acted on: [Re, Im, 0](e^{-i theta} f) F (the row-vector
    form of :mod:`hiab_sim.machine.dynamics.newton_euler`). Both are new arrays.
    """
    layout = ws.layout
    n, on = layout.n_bodies - 1, layout.pins_on
    P = n + lam.shape[0]
    world = np.empty((*ws.shape, P), dtype=complex)
    world[..., :n] = transmitted[1:].transpose(1, 2, 0)
    world[..., n:] = lam.transpose(1, 2, 0)
    unturn = ws.c("pin-frame", P)
    ws.rot.take(on, out=unturn, axis=0, mode="clip")
    np.conjugate(unturn, out=unturn)
    turned = ws.buffer("pin-turned", world.shape, complex)
    np.multiply(world, unturn.transpose(1, 2, 0), out=turned)
    fixed = layout.fixed[on]
    local = np.multiply(turned.real[..., None], fixed[:, 0, :])
    spare = ws.buffer("pin-local", local.shape, float)
    np.multiply(turned.imag[..., None], fixed[:, 1, :], out=spare)
    local += spare
    return world.view(np.float64).reshape(*world.shape, 2), local

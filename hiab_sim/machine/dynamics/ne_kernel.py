"""The motion half of the Newton-Euler solve: every body's frame, vectorised over designs and samples.

Arrays are body-major, (nbody, D, T) for D designs and T samples (or chains, pins first), so a
body's row is contiguous; each design's numbers
(:class:`~hiab_sim.machine.dynamics.ne_layout.NeConstants`, (n, D)) broadcast over its samples.
No Python loop runs over samples or designs, only over bodies. Every array lives in a
:class:`Workspace` kept from call to call and is written in place (``out=``): at these sizes
fresh temporaries cost more than the arithmetic (each one is new memory from the system).

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

import threading
from collections import OrderedDict

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


class Workspace:
    """Frames, coordinates and scratch arrays of one evaluation of D designs x T samples.

    Frames: ``rot`` (nbody, D, T) e^{i theta}; ``motion`` (3, nbody, D, T) the origin's position,
    velocity and acceleration (complex) [m, m/s, m/s^2]; ``factor`` (3, nbody, D, T) = (1, i omega,
    i alpha - omega^2), so that a point at arm r e^{i theta} from the origin moves with
    motion + factor r e^{i theta}; ``omega``, ``alpha`` [rad/s, rad/s^2]; full coordinates ``q``,
    ``dq``, ``ddq``; scratch arrays by name (:meth:`c`, :meth:`r`, :meth:`buffer`). The root's row
    is set once: at the root's origin, unrotated, at rest.
    """

    def __init__(self, layout: NeLayout, designs: int, samples: int) -> None:
        self.layout, self.shape = layout, (designs, samples)
        shape = (layout.n_bodies, designs, samples)
        self.rot = np.zeros(shape, complex)
        self.motion, self.factor = np.zeros((3, *shape), complex), np.zeros((3, *shape), complex)
        self.omega, self.alpha, self.q, self.dq, self.ddq = (np.zeros(shape) for _ in range(5))
        self.rot[0] = 1.0
        self.factor[0] = 1.0
        self.motion[0, 0] = layout.file.origin[0, 0]  # the root carries no decision variable
        self._scratch: dict[str, np.ndarray] = {}

    @property
    def nbytes(self) -> int:
        """Memory held [bytes]."""
        arrays = (self.rot, self.motion, self.factor, self.omega, self.alpha, self.q, self.dq, self.ddq)
        return sum(a.nbytes for a in arrays) + sum(a.nbytes for a in self._scratch.values())

    def c(self, name: str, *rows: int) -> Complex:
        """Complex scratch array (*rows, D, T) of this name (contents left from its last use)."""
        return self.buffer(f"{name} (complex)", (*rows, *self.shape), complex)

    def r(self, name: str, *rows: int) -> Array:
        """Real scratch array (*rows, D, T) of this name."""
        return self.buffer(f"{name} (real)", (*rows, *self.shape), float)

    def buffer(self, name: str, shape: tuple[int, ...], dtype: type) -> np.ndarray:
        """Scratch array of this name (one shape and type per name; zeros when new)."""
        out = self._scratch.get(name)
        if out is None:
            out = np.zeros(shape, dtype)
            self._scratch[name] = out
        return out

    def orient(self, bodies: Index, rot: Complex, omega: Array, alpha: Array, factor: Complex) -> Complex:
        """Set e^{i theta}, omega, alpha of ``bodies``; ``factor`` (3, k, D, T) gets (1, i omega, i alpha - omega^2)."""
        self.rot[bodies], self.omega[bodies], self.alpha[bodies] = rot, omega, alpha
        factor[0] = 1.0
        np.multiply(omega, 1j, out=factor[1])
        np.multiply(alpha, 1j, out=factor[2])
        factor[2] -= omega * omega
        self.factor[1:, bodies] = factor[1:]
        return factor

    def points(self, bodies: Index, r: Complex, out: Complex, spare: tuple[Complex, Complex]) -> Complex:
        """Motion (3, k, D, T) of planar points r ((k, D, 1) or (k, 1, 1)) of ``bodies`` into ``out``.

        ``spare``: scratch (k, D, T) and (3, k, D, T).
        """
        arm, tmp = spare
        self.rot.take(bodies, axis=0, out=arm, mode="clip")
        arm *= r
        self.motion.take(bodies, axis=1, out=out, mode="clip")
        self.factor.take(bodies, axis=1, out=tmp, mode="clip")
        tmp *= arm
        out += tmp
        return out


class _Workspaces(threading.local):
    """Per thread: the workspaces used last (one thread's calls never share arrays with another's)."""

    def __init__(self) -> None:
        self.kept: OrderedDict[tuple[int, int, int], Workspace] = OrderedDict()


_KEPT = _Workspaces()
_KEEP = 3  # shapes kept per thread: an optimiser alternates a few (K, 18 K and 12 x K samples)
_KEEP_BYTES = 96 * 2**20  # a larger workspace is built per call and let go


def workspace(layout: NeLayout, designs: int, samples: int) -> Workspace:
    """The workspace of this layout and shape, reused when it was used recently in this thread."""
    key = (id(layout), designs, samples)
    ws = _KEPT.kept.get(key)
    if ws is not None and ws.layout is layout:
        _KEPT.kept.move_to_end(key)
        return ws
    ws = Workspace(layout, designs, samples)
    if 40 * ws.q.nbytes <= _KEEP_BYTES:  # about 40 (nbody, D, T) arrays in all (frames, forces, scratch)
        _KEPT.kept[key] = ws
        while len(_KEPT.kept) > _KEEP:
            _KEPT.kept.popitem(last=False)
    return ws


def forward(ws: Workspace, c: NeConstants, bodies: range) -> None:
    """Frames of ``bodies`` (parents first, each parent's frame known) from ``ws.q``, ``dq``, ``ddq`` (step 1)."""
    layout = ws.layout
    q, dq, ddq, motion, factor = ws.q, ws.dq, ws.ddq, ws.motion, ws.factor
    w, u, tmp = ws.c("forward", 3)
    moved = ws.c("forward-motion", 3)
    square = ws.r("forward")
    for b in bodies:
        p = layout.parent[b]
        origin = c.origin[b][:, None]
        if layout.revolute[b]:
            np.multiply(q[b], 1j, out=tmp)
            np.exp(tmp, out=tmp)
            np.multiply(ws.rot[p], tmp, out=ws.rot[b])
            np.add(ws.omega[p], dq[b], out=ws.omega[b])
            np.add(ws.alpha[p], ddq[b], out=ws.alpha[b])
            np.multiply(ws.omega[b], 1j, out=factor[1, b])
            np.multiply(ws.alpha[b], 1j, out=factor[2, b])
            np.multiply(ws.omega[b], ws.omega[b], out=square)
            factor[2, b] -= square
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


def close_chains(ws: Workspace, c: NeConstants, angles: bool = False) -> None:
    """Chain bodies' frames and the rods' coordinates (with ``angles`` every chain joint's) (step 2).

    The links' frames must be filled. Chain hinge coordinates are written only with ``angles``
    (nothing else needs them).

    Raises:
        InvalidInputError: a four-bar that cannot close (field ``chains.<chain>.linkage``).

    """
    layout = ws.layout
    g = layout.groups
    n_tri, k = len(g.tri_chain), len(g.tri_chain) + len(g.bar_chain)
    if k == 0:
        return
    end, pivot, spare = ws.c("end", 3, k), ws.c("pivot", 3, k), ws.c("spare", 3, k)
    e, arm = ws.c("e", k), ws.c("arm", k)
    ws.points(g.tri_end, c.point_b[g.tri_loop][:, :, None], end[:, :n_tri], (arm[:n_tri], spare[:, :n_tri]))
    cyl, rod, base, x0 = g.tri_cyl, g.tri_rod, g.tri_base, c.x0[g.tri_chain]
    if k > n_tri:
        end[:, n_tri:] = _four_bar(ws, c, angles)
        cyl, rod, base = np.concatenate([cyl, g.bar_cyl]), np.concatenate([rod, g.bar_rod]), np.concatenate([base, g.bar_base])
        x0 = np.concatenate([x0, c.x0[g.bar_chain]])
    ws.points(base, c.origin[cyl][:, :, None], pivot, (arm, spare))
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
    e *= layout.unturn[cyl][:, None, None]  # the cylinder's e^{i theta}
    turning = ws.orient(cyl, e, omega, alpha, ws.c("turning", 3, k))
    ws.rot[rod], ws.omega[rod], ws.alpha[rod] = e, omega, alpha  # a slide turns with its cylinder
    ws.factor[1:, rod] = turning[1:]
    ws.motion[:, cyl] = pivot
    x = s
    x -= x0[:, :, None]  # stroke s - x0 (s is not needed any more)
    ws.q[rod], ws.dq[rod], ws.ddq[rod] = x, dx, ddx
    u, w = end[0], end[1]  # d, v_d are not needed any more either
    np.multiply(e, layout.axis[rod][:, None, None], out=u)
    np.multiply(e, c.origin[rod][:, :, None], out=w)
    np.multiply(u, x, out=arm)
    w += arm
    moved = ws.c("rod motion", 3, k)
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


def _four_bar(ws: Workspace, c: NeConstants, angles: bool) -> Complex:
    """Rocker and coupler frames (and coordinates); return the rod pin H's motion (3, n, D, T)."""
    layout = ws.layout
    g = layout.groups
    n = len(g.bar_chain)
    J, K = ws.c("four-bar J", 3, n), ws.c("four-bar K", 3, n)
    spare = (ws.c("four-bar arm", n), ws.c("four-bar spare", 3, n))
    ws.points(g.bar_j, c.origin[g.bar_rocker][:, :, None], J, spare)
    ws.points(g.bar_k, c.point_b[g.bar_loop][:, :, None], K, spare)
    r1, r2, side = (x[:, None, None] for x in (g.bar_r1, g.bar_r2, g.bar_side))
    span = np.abs(K[0] - J[0])
    along = (span * span + r1 * r1 - r2 * r2) / (2.0 * span)
    height2 = r1 * r1 - along * along
    if np.any(height2 < 0.0):
        k = int(np.argmax(np.any(height2 < 0.0, axis=(1, 2))))
        low, high = abs(g.bar_r1[k] - g.bar_r2[k]), g.bar_r1[k] + g.bar_r2[k]
        raise InvalidInputError(
            f"chains.{g.bar_names[k]}.linkage", f"|K - J| = {float(span[k][height2[k] < 0.0][0]):.6g} m",
            f"must lie in [{low:.6g}, {high:.6g}] for the four-bar to close", "m",
        )  # fmt: skip
    H = J[0] + (K[0] - J[0]) / span * (along + 1j * side * np.sqrt(height2))
    arm, reach = H - J[0], K[0] - H  # rocker J -> H, coupler H -> K
    v, a = K[1] - J[1], K[2] - J[2]
    turn = cross(arm, reach)
    w_r, w_c = dot(reach, v) / turn, -dot(arm, v) / turn
    rest = a + w_r * w_r * arm + w_c * w_c * reach
    a_r, a_c = dot(reach, rest) / turn, -dot(arm, rest) / turn
    rocker, coupler, link = g.bar_rocker, g.bar_coupler, g.bar_j
    factor = ws.c("four-bar factor", 3, n)
    ws.orient(rocker, arm / r1 * layout.unturn[rocker][:, None, None], w_r, a_r, factor)
    ws.motion[:, rocker] = J
    ws.orient(coupler, reach / r2 * layout.unturn[coupler][:, None, None], w_c, a_c, factor)
    H_motion = np.stack([H, J[1] + 1j * w_r * arm, J[2] + (1j * a_r - w_r * w_r) * arm])
    ws.motion[:, coupler] = H_motion
    if angles:
        ws.q[rocker] = np.angle(ws.rot[rocker] * ws.rot[link].conj())
        ws.dq[rocker], ws.ddq[rocker] = w_r - ws.omega[link], a_r - ws.alpha[link]
        ws.q[coupler] = np.angle(reach * arm.conj())
        ws.dq[coupler], ws.ddq[coupler] = w_c - w_r, a_c - a_r
    return H_motion


def full_state(
    layout: NeLayout, c: NeConstants, q: Array, dq: Array, ddq: Array, angles: bool = False, keep: bool = True
) -> Workspace:
    """Full coordinates, rates, accelerations (nbody, D, T) and every body's frame, in a workspace.

    ``q``, ``dq``, ``ddq``: the independent joints (n_joints, 1 or D, T), unchecked. Chain hinge
    entries are filled only with ``angles`` (the rods' always). ``keep``: take a kept workspace
    (its arrays are overwritten by the next call in this thread: copy what is returned).
    """
    D, T = max(c.designs, q.shape[1]), q.shape[2]
    ws = workspace(layout, D, T) if keep else Workspace(layout, D, T)
    for array, given in zip((ws.q, ws.dq, ws.ddq), (q, dq, ddq), strict=True):
        array[layout.independent] = given
    forward(ws, c, range(1, layout.n_links))
    close_chains(ws, c, angles=angles)
    return ws


def frames_of_full(layout: NeLayout, c: NeConstants, q: Array, dq: Array, ddq: Array) -> Workspace:
    """Every body's frame for full coordinates (nbody, D, T) as they are (no loop closure), in a new workspace."""
    ws = Workspace(layout, q.shape[1], q.shape[2])
    ws.q[...], ws.dq[...], ws.ddq[...] = q, dq, ddq
    forward(ws, c, range(1, layout.n_bodies))
    return ws

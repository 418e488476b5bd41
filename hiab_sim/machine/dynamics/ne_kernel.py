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

    Frames, (nbody, D, T): ``rot`` e^{i theta}, origins ``z``, ``dz``, ``ddz`` (complex) [m, m/s,
    m/s^2], ``omega``, ``alpha`` [rad/s, rad/s^2], ``spin`` = i omega and ``turn`` = i alpha -
    omega^2 (a point's velocity and acceleration relative to the origin are spin and turn times
    its arm); full coordinates ``q``, ``dq``, ``ddq``; scratch arrays by name (:meth:`c`, :meth:`r`).
    The root's row is set once: at the root's origin, unrotated, at rest.
    """

    def __init__(self, layout: NeLayout, designs: int, samples: int) -> None:
        self.layout, self.shape = layout, (designs, samples)
        shape = (layout.n_bodies, designs, samples)
        self.rot, self.z, self.dz, self.ddz, self.spin, self.turn = (np.zeros(shape, complex) for _ in range(6))
        self.omega, self.alpha, self.q, self.dq, self.ddq = (np.zeros(shape) for _ in range(5))
        self.rot[0] = 1.0
        self.z[0] = layout.file.origin[0, 0]  # the root carries no decision variable
        self._scratch: dict[tuple[str, tuple[int, ...], type], np.ndarray] = {}

    @property
    def nbytes(self) -> int:
        """Memory held [bytes]."""
        arrays = (self.rot, self.z, self.dz, self.ddz, self.spin, self.turn, self.omega, self.alpha)
        return sum(a.nbytes for a in arrays) + 3 * self.q.nbytes + sum(a.nbytes for a in self._scratch.values())

    def c(self, name: str, rows: int) -> Complex:
        """Complex scratch array (rows, D, T) of this name (contents left from its last use)."""
        return self.buffer(name, (rows, *self.shape), complex)

    def r(self, name: str, rows: int) -> Array:
        """Real scratch array (rows, D, T) of this name."""
        return self.buffer(name, (rows, *self.shape), float)

    def buffer(self, name: str, shape: tuple[int, ...], dtype: type) -> np.ndarray:
        """Scratch array of this name, shape and type (zeros when new)."""
        key = (name, shape, dtype)
        out = self._scratch.get(key)
        if out is None:
            out = np.zeros(shape, dtype)
            self._scratch[key] = out
        return out

    def orient(self, bodies: Index, rot: Complex, omega: Array, alpha: Array, spare: tuple[Complex, Array]) -> None:
        """Set e^{i theta}, omega, alpha (and spin, turn) of ``bodies``; ``spare``: scratch of their shape."""
        tmp, square = spare
        self.rot[bodies], self.omega[bodies], self.alpha[bodies] = rot, omega, alpha
        np.multiply(omega, 1j, out=tmp)
        self.spin[bodies] = tmp
        np.multiply(alpha, 1j, out=tmp)
        np.multiply(omega, omega, out=square)
        tmp -= square
        self.turn[bodies] = tmp

    def points(self, bodies: Index, r: Complex, out: Motion, spare: tuple[Complex, Complex]) -> Motion:
        """Position, velocity, acceleration of planar points r ((k, D, 1) or (k, 1, 1)) of ``bodies`` into ``out``."""
        arm, tmp = spare
        p, v, a = out
        np.take(self.rot, bodies, axis=0, out=arm, mode="clip")
        arm *= r
        np.take(self.z, bodies, axis=0, out=p, mode="clip")
        p += arm
        np.take(self.spin, bodies, axis=0, out=tmp, mode="clip")
        tmp *= arm
        np.take(self.dz, bodies, axis=0, out=v, mode="clip")
        v += tmp
        np.take(self.turn, bodies, axis=0, out=tmp, mode="clip")
        tmp *= arm
        np.take(self.ddz, bodies, axis=0, out=a, mode="clip")
        a += tmp
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
    q, dq, ddq = ws.q, ws.dq, ws.ddq
    w, u, tmp = ws.c("fw", 3)
    square = ws.r("fw", 1)[0]
    for b in bodies:
        p = layout.parent[b]
        origin = c.origin[b][:, None]
        if layout.revolute[b]:
            np.multiply(q[b], 1j, out=tmp)
            np.exp(tmp, out=tmp)
            np.multiply(ws.rot[p], tmp, out=ws.rot[b])
            np.add(ws.omega[p], dq[b], out=ws.omega[b])
            np.add(ws.alpha[p], ddq[b], out=ws.alpha[b])
            np.multiply(ws.omega[b], 1j, out=ws.spin[b])
            np.multiply(ws.alpha[b], 1j, out=ws.turn[b])
            np.multiply(ws.omega[b], ws.omega[b], out=square)
            ws.turn[b] -= square
            np.multiply(ws.rot[p], origin, out=w)
            np.add(ws.z[p], w, out=ws.z[b])
            np.multiply(ws.spin[p], w, out=tmp)
            np.add(ws.dz[p], tmp, out=ws.dz[b])
            np.multiply(ws.turn[p], w, out=tmp)
            np.add(ws.ddz[p], tmp, out=ws.ddz[b])
            continue
        for series in (ws.rot, ws.omega, ws.alpha, ws.spin, ws.turn):  # a slide turns with its parent
            series[b] = series[p]
        np.multiply(ws.rot[p], layout.axis[b], out=u)
        np.multiply(ws.rot[p], origin, out=w)
        np.multiply(u, q[b], out=tmp)
        w += tmp
        np.add(ws.z[p], w, out=ws.z[b])
        np.multiply(ws.spin[p], w, out=tmp)
        np.add(ws.dz[p], tmp, out=ws.dz[b])
        np.multiply(u, dq[b], out=tmp)
        ws.dz[b] += tmp
        np.multiply(ws.turn[p], w, out=tmp)
        np.add(ws.ddz[p], tmp, out=ws.ddz[b])
        np.multiply(ws.spin[p], u, out=tmp)
        tmp *= dq[b]
        tmp *= 2.0
        ws.ddz[b] += tmp
        np.multiply(u, ddq[b], out=tmp)
        ws.ddz[b] += tmp


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
    end = ws.c("end", 3 * k).reshape(3, k, *ws.shape)
    pivot = ws.c("pivot", 3 * k).reshape(3, k, *ws.shape)
    spare = ws.c("spare", 2 * k).reshape(2, k, *ws.shape)
    ends = (end[0, :n_tri], end[1, :n_tri], end[2, :n_tri])
    ws.points(g.tri_end, c.point_b[g.tri_loop][:, :, None], ends, (spare[0, :n_tri], spare[1, :n_tri]))
    cyl, rod, base, x0 = g.tri_cyl, g.tri_rod, g.tri_base, c.x0[g.tri_chain]
    if k > n_tri:
        H = _four_bar(ws, c, angles)
        for series, h in zip(end, H, strict=True):
            series[n_tri:] = h
        cyl, rod, base = np.concatenate([cyl, g.bar_cyl]), np.concatenate([rod, g.bar_rod]), np.concatenate([base, g.bar_base])
        x0 = np.concatenate([x0, c.x0[g.bar_chain]])
    ws.points(base, c.origin[cyl][:, :, None], (pivot[0], pivot[1], pivot[2]), (spare[0], spare[1]))
    d, v, a = end[0], end[1], end[2]
    d -= pivot[0]
    v -= pivot[1]
    a -= pivot[2]
    s, inv, omega, alpha, ddx, tmp = ws.r("triangle", 6 * k).reshape(6, k, *ws.shape)
    e, ev, ea = spare[0], spare[1], ws.c("ea", k)
    np.abs(d, out=s)
    np.divide(1.0, s, out=inv)
    np.multiply(d, inv, out=e)  # e = d / s
    np.conjugate(e, out=ea)
    np.multiply(ea, v, out=ev)  # e* v_d
    ea *= a  # e* a_d
    dx = ev.real
    np.multiply(ev.imag, inv, out=omega)
    np.multiply(omega, omega, out=ddx)
    ddx *= s
    ddx += ea.real
    np.multiply(dx, omega, out=alpha)
    alpha *= -2.0
    alpha += ea.imag
    alpha *= inv
    rot, u, w, t = ws.c("cylinder", 4 * k).reshape(4, k, *ws.shape)
    np.multiply(e, layout.unturn[cyl][:, None, None], out=rot)
    ws.orient(cyl, rot, omega, alpha, (t, tmp))
    ws.z[cyl], ws.dz[cyl], ws.ddz[cyl] = pivot
    ws.orient(rod, rot, omega, alpha, (t, tmp))
    x = s
    x -= x0[:, :, None]  # stroke: s - x0 (s is no longer needed)
    ws.q[rod], ws.dq[rod], ws.ddq[rod] = x, dx, ddx
    np.multiply(rot, layout.axis[rod][:, None, None], out=u)
    np.multiply(rot, c.origin[rod][:, :, None], out=w)
    np.multiply(u, x, out=t)
    w += t
    spin, turn = ws.spin[cyl], ws.turn[cyl]
    np.add(pivot[0], w, out=t)
    ws.z[rod] = t
    np.multiply(spin, w, out=t)
    t += pivot[1]
    ea[...] = u
    ea *= dx
    t += ea
    ws.dz[rod] = t
    np.multiply(turn, w, out=t)
    t += pivot[2]
    np.multiply(spin, u, out=ea)
    ea *= dx
    ea *= 2.0
    t += ea
    np.multiply(u, ddx, out=ea)
    t += ea
    ws.ddz[rod] = t
    if angles:
        ws.q[cyl] = np.angle(rot * ws.rot[base].conj())
        ws.dq[cyl], ws.ddq[cyl] = omega - ws.omega[base], alpha - ws.alpha[base]


def _four_bar(ws: Workspace, c: NeConstants, angles: bool) -> Motion:
    """Rocker and coupler frames (and coordinates); return the rod pin H's position, velocity, acceleration."""
    layout = ws.layout
    g = layout.groups
    n = len(g.bar_chain)
    buffers = ws.c("four-bar", 8 * n).reshape(8, n, *ws.shape)
    J = ws.points(g.bar_j, c.origin[g.bar_rocker][:, :, None], tuple(buffers[:3]), (buffers[6], buffers[7]))  # type: ignore[arg-type]
    K = ws.points(g.bar_k, c.point_b[g.bar_loop][:, :, None], tuple(buffers[3:6]), (buffers[6], buffers[7]))  # type: ignore[arg-type]
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
    H_motion = (H, J[1] + 1j * w_r * arm, J[2] + (1j * a_r - w_r * w_r) * arm)
    spare = (buffers[6], ws.r("four-bar", n))
    ws.orient(rocker, arm / r1 * layout.unturn[rocker][:, None, None], w_r, a_r, spare)
    ws.z[rocker], ws.dz[rocker], ws.ddz[rocker] = J
    ws.orient(coupler, reach / r2 * layout.unturn[coupler][:, None, None], w_c, a_c, spare)
    ws.z[coupler], ws.dz[coupler], ws.ddz[coupler] = H_motion
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

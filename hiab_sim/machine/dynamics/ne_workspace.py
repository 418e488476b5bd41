"""Arrays of the Newton-Euler solve, kept from call to call, and each design's numbers shaped for it.

The solve (:mod:`hiab_sim.machine.dynamics.ne_kernel`, :mod:`hiab_sim.machine.dynamics.ne_forces`)
writes every intermediate array in place (``out=``) into a :class:`Workspace`: at the sizes an
optimiser asks for (a few thousand samples) a fresh temporary costs more than the arithmetic on
it, since it is new memory from the system each time. Arrays are body-major, (nbody, D, T) for
D designs and T samples (or chains, pins first), so that a body's row is contiguous.
:class:`Prepared` holds a design's numbers (:class:`~hiab_sim.machine.dynamics.ne_layout.NeConstants`)
gathered and shaped to broadcast over the samples, built once per ID object or batch.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.machine.dynamics.ne_layout import NeConstants, NeLayout

Complex = NDArray[np.complex128]
Index = NDArray[np.intp]


class Workspace:
    """Frames, coordinates and scratch arrays of one evaluation of D designs x T samples.

    Frames: ``rot`` (nbody, D, T) e^{i theta}; ``motion`` (3, nbody, D, T) the origin's position,
    velocity and acceleration (complex) [m, m/s, m/s^2]; ``factor`` (3, nbody, D, T) = (1, i omega,
    i alpha - omega^2), so that a point at arm r e^{i theta} from the origin moves with
    motion + factor r e^{i theta}; ``omega``, ``alpha`` [rad/s, rad/s^2]; full coordinates ``q``,
    ``dq``, ``ddq``; scratch arrays by name (:meth:`c`, :meth:`r`, :meth:`buffer`). The root's row is set once:
    at the root's origin, unrotated, at rest.
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
        self._complex: dict[object, Complex] = {}
        self._real: dict[object, Array] = {}

    def c(self, name: object, *rows: int) -> Complex:
        """Complex scratch array (*rows, D, T) of this name (one shape per name; contents from its last use)."""
        out = self._complex.get(name)
        if out is None:
            out = self._complex[name] = np.zeros((*rows, *self.shape), complex)
        return out

    def r(self, name: object, *rows: int) -> Array:
        """Real scratch array (*rows, D, T) of this name."""
        out = self._real.get(name)
        if out is None:
            out = self._real[name] = np.zeros((*rows, *self.shape))
        return out

    def buffer(self, name: str, shape: tuple[int, ...], dtype: type) -> np.ndarray:
        """Scratch array of any shape (one shape per name)."""
        store = self._complex if dtype is complex else self._real
        out = store.get(name)
        if out is None:
            out = store[name] = np.zeros(shape, dtype)
        return out

    def orient(self, bodies: Index, rot: Complex, omega: Array, alpha: Array, factor: Complex) -> Complex:
        """Set e^{i theta}, omega, alpha of ``bodies`` ((k,) or (2, k) for two bodies turning alike).

        ``factor`` (3, k, D, T) is filled with (1, i omega, i alpha - omega^2) and returned.
        """
        self.rot[bodies], self.omega[bodies], self.alpha[bodies] = rot, omega, alpha
        factor[0] = 1.0
        np.multiply(omega, 1j, out=factor[1])
        np.multiply(alpha, 1j, out=factor[2])
        square = self.r(("orient", omega.shape), *omega.shape[:-2])
        np.multiply(omega, omega, out=square)
        factor[2] -= square
        self.factor[1:, bodies] = factor[1:, None] if bodies.ndim == 2 else factor[1:]
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


@dataclass(frozen=True)
class Prepared:
    """A design's numbers gathered and shaped for the solve ((k, D, 1) or (k, 1, 1) against (k, D, T)).

    ``origin`` (nbody, D, 1) joint origins; actuator triangles (triangles, then four-bars):
    ``cyl``, ``rod``, ``base`` bodies, ``pair`` (2, k) = (cyl, rod), ``cyl_origin`` (the base
    pivot), ``x0``, ``unturn`` e^{-i offset} of the cylinder, ``rod_axis``, ``rod_origin``;
    ``tri_end``: a triangle's end pivot on its link; ``bar_j``, ``bar_k``: a four-bar's pivots J, K;
    massive bodies' ``com``, ``mass``, ``izz``; ``side_point``: each hinge-equation entry's pin
    point; ``signs``: per pin level, the signs of its two equations; ``act_axis``: actuated slides'
    axes.
    """

    constants: NeConstants
    origin: Complex
    cyl: Index
    rod: Index
    base: Index
    pair: Index
    cyl_origin: Complex
    x0: Array
    unturn: Complex
    rod_axis: Complex
    rod_origin: Complex
    tri_end: Complex
    bar_j: Complex
    bar_k: Complex
    com: Complex
    mass: Array
    izz: Array
    side_point: Complex
    signs: tuple[tuple[Array, Array], ...]
    act_axis: Complex

    @property
    def designs(self) -> int:
        """Number of designs D."""
        return self.constants.designs


def prepare(layout: NeLayout, c: NeConstants) -> Prepared:
    """The design numbers ``c`` shaped for the solve of ``layout``."""
    g, s, mb = layout.groups, layout.system, layout.massive
    cyl, rod = np.concatenate([g.tri_cyl, g.bar_cyl]), np.concatenate([g.tri_rod, g.bar_rod])
    chains = np.concatenate([g.tri_chain, g.bar_chain])

    def col(values: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(values[:, :, None])

    def const(values: np.ndarray) -> np.ndarray:
        return np.asarray(values)[:, None, None]

    points = np.concatenate([c.point_a, c.point_b])
    return Prepared(
        constants=c,
        origin=col(c.origin),
        cyl=cyl,
        rod=rod,
        base=np.concatenate([g.tri_base, g.bar_base]),
        pair=np.stack([cyl, rod]),
        cyl_origin=col(c.origin[cyl]),
        x0=col(c.x0[chains]),
        unturn=const(layout.unturn[cyl]),
        rod_axis=const(layout.axis[rod]),
        rod_origin=col(c.origin[rod]),
        tri_end=col(c.point_b[g.tri_loop]),
        bar_j=col(c.origin[g.bar_rocker]),
        bar_k=col(c.point_b[g.bar_loop]),
        com=col(c.com[mb]),
        mass=col(c.mass[mb]),
        izz=col(c.izz[mb]),
        side_point=col(points[s.pin + len(layout.tree.loops) * s.side]),
        signs=tuple((const(s.sign[e1]), const(s.sign[e2])) for _, e1, e2, _, _ in s.levels),
        act_axis=const(layout.axis[layout.actuated]),
    )

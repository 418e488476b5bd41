"""Generic numeric loop closure: any chain as planar vector loops solved by Newton's method.

Independent of the closed forms of :mod:`hiab_sim.machine.kinematics.closure` (the tests compare the two).
A chain's loops are written in the frame P of the driven joint's parent as sums of terms
``rho_k u(alpha_k)`` plus a constant vector, u(a) = (cos a, sin a), where each ``alpha_k`` is
affine in the loop variables v = [q, s, theta_cyl, (theta_rocker, theta_coupler)] and ``rho_k`` is
a constant or the actuator length s:

* triangle (one loop): (end - base) + (hinge - end) + (base - hinge) = 0, i.e.
  s u(theta_cyl) -/+ |c| u(phi + q + arg c) + const = 0 (c: the pivot on the driven link);
* linkage (two loops): (H - b) + (r - H) + (b - r) = 0 and (H - r) + (C - H) + (h - C) + (r - h) = 0.

Given q, Newton's method solves F(v) = 0 for the other variables; the first and second
derivatives with respect to q follow from the linear systems F_d v_d' = -F_q and
F_d v_d'' = -sum_k (2 rho_k' alpha_k' J u_k - rho_k alpha_k'^2 u_k) (the second time derivative of
each term, J the +90 deg turn). Vectorised over samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.machine.description import Chain, Machine
from hiab_sim.machine.kinematics.closure import ChainGeometry, Closure, chain_geometry

#: Newton stops when every loop residual is below this [m].
RESIDUAL_TOLERANCE = 1e-13
MAX_ITERATIONS = 60


@dataclass(frozen=True)
class Term:
    """rho u(alpha): ``length`` (constant) or the variable ``length_var``; alpha = angle0 + coeffs . v."""

    length: float
    length_var: int | None
    angle0: float
    coeffs: tuple[float, ...]


@dataclass(frozen=True)
class Loop:
    """Sum of terms plus a constant 2-vector, which must vanish."""

    terms: tuple[Term, ...]
    constant: tuple[float, float]


def chain_loops(geo: ChainGeometry) -> tuple[tuple[Loop, ...], dict[str, int]]:
    """The chain's loops and the index of each body angle in v (see the module docstring)."""
    if geo.kind == "triangle":
        role = "end" if "end" in geo.moving else "base"
        fixed_role = "base" if role == "end" else "end"
        c = geo.moving[role]
        # end - base = s u(th); moving end: hinge - end = |c| u(phi + q + arg c + pi), base - hinge const;
        # moving base: base - hinge = |c| u(phi + q + arg c), hinge - end const.
        turn = np.pi if role == "end" else 0.0
        const = geo.fixed[fixed_role] - geo.hinge if role == "end" else geo.hinge - geo.fixed[fixed_role]
        loop = Loop(
            (
                Term(0.0, 1, 0.0, (0.0, 0.0, 1.0)),
                Term(float(np.hypot(*c)), None, geo.phi + float(np.arctan2(c[1], c[0])) + turn, (1.0, 0.0, 0.0)),
            ),
            (float(const[0]), float(const[1])),
        )
        return (loop,), {"cylinder": 2}
    b, r, c = geo.fixed["base"], geo.fixed["rocker"], geo.moving["coupler"]
    n = 5
    unit = np.eye(n)
    loop1 = Loop(
        (Term(0.0, 1, 0.0, tuple(unit[2])), Term(geo.rocker_length, None, np.pi, tuple(unit[3]))),
        (float(b[0] - r[0]), float(b[1] - r[1])),
    )
    loop2 = Loop(
        (
            Term(geo.rocker_length, None, 0.0, tuple(unit[3])),
            Term(geo.coupler_length, None, 0.0, tuple(unit[4])),
            Term(float(np.hypot(*c)), None, geo.phi + float(np.arctan2(c[1], c[0])) + np.pi, tuple(unit[0])),
        ),
        (float(r[0] - geo.hinge[0]), float(r[1] - geo.hinge[1])),
    )
    return (loop1, loop2), {"cylinder": 2, "rocker": 3, "coupler": 4}


def _unit(a: Array) -> Array:
    return np.stack([np.cos(a), np.sin(a)], axis=-1)


def _turned(a: Array) -> Array:
    return np.stack([-np.sin(a), np.cos(a)], axis=-1)


def _evaluate(loops: tuple[Loop, ...], v: Array, dv: Array | None = None) -> tuple[Array, Array, Array]:
    """Residual F (..., 2m), Jacobian F_v (..., 2m, n) and, given dv, the quadratic terms (..., 2m)."""
    n = v.shape[-1]
    residual, jacobian, quadratic = [], [], []
    for loop in loops:
        f = np.broadcast_to(np.asarray(loop.constant), (*v.shape[:-1], 2)).copy()
        jac = np.zeros((*v.shape[:-1], 2, n))
        quad = np.zeros((*v.shape[:-1], 2))
        for term in loop.terms:
            coeffs = np.asarray(term.coeffs)
            alpha = term.angle0 + v @ coeffs
            rho = v[..., term.length_var] if term.length_var is not None else np.full(v.shape[:-1], term.length)
            u, ju = _unit(alpha), _turned(alpha)
            f += rho[..., None] * u
            jac += (rho[..., None] * ju)[..., None] * coeffs
            if term.length_var is not None:
                jac[..., term.length_var] += u
            if dv is not None:
                d_alpha = dv @ coeffs
                d_rho = dv[..., term.length_var] if term.length_var is not None else 0.0
                quad += (2.0 * d_rho * d_alpha)[..., None] * ju - (rho * d_alpha**2)[..., None] * u
        residual.append(f)
        jacobian.append(jac)
        quadratic.append(quad)
    return np.concatenate(residual, -1), np.concatenate(jacobian, -2), np.concatenate(quadratic, -1)


def _initial_guess(geo: ChainGeometry, q: Array) -> Array:
    """A starting point on the chain's assembly branch, from the declared geometry only."""
    angle = geo.phi + q
    rot = np.stack([np.stack([np.cos(angle), -np.sin(angle)], -1), np.stack([np.sin(angle), np.cos(angle)], -1)], -2)

    def moving(local: Array) -> Array:
        return geo.hinge + rot @ local

    if geo.kind == "triangle":
        base = moving(geo.moving["base"]) if "base" in geo.moving else np.broadcast_to(geo.fixed["base"], (*q.shape, 2))
        end = moving(geo.moving["end"]) if "end" in geo.moving else np.broadcast_to(geo.fixed["end"], (*q.shape, 2))
        v = end - base
        return np.stack([q, np.hypot(v[..., 0], v[..., 1]), np.arctan2(v[..., 1], v[..., 0])], -1)
    r, b = geo.fixed["rocker"], geo.fixed["base"]
    C = moving(geo.moving["coupler"])
    to_c = np.arctan2(C[..., 1] - r[1], C[..., 0] - r[0])
    theta_r = to_c + geo.pin_side * np.pi / 2.0
    H = r + geo.rocker_length * _unit(theta_r)
    cyl, cpl = H - b, C - H
    return np.stack(
        [
            q,
            np.hypot(cyl[..., 0], cyl[..., 1]),
            np.arctan2(cyl[..., 1], cyl[..., 0]),
            theta_r,
            np.arctan2(cpl[..., 1], cpl[..., 0]),
        ],
        -1,
    )


def numeric_closure(machine: Machine, chain: Chain, q: ArrayLike) -> Closure:
    """Loop closure by Newton's method on the chain's vector loops; the same fields as the closed form."""
    geo = chain_geometry(machine, chain)
    q = np.asarray(q, dtype=float)
    if geo.kind == "direct":
        zero = np.zeros_like(q)
        return Closure(geo.x0 + q, np.ones_like(q), zero, {}, {}, {}, np.ones(q.shape, dtype=bool))
    loops, names = chain_loops(geo)
    v = _initial_guess(geo, q)
    for _ in range(MAX_ITERATIONS):
        f, jac, _ = _evaluate(loops, v)
        if np.all(np.abs(f) < RESIDUAL_TOLERANCE):
            break
        step = np.linalg.solve(jac[..., 1:], -f[..., None])[..., 0]
        v[..., 1:] += step
    f, jac, _ = _evaluate(loops, v)
    closes = np.all(np.abs(f) < 1e3 * RESIDUAL_TOLERANCE, axis=-1) & (v[..., 1] > 0.0)
    dv = np.zeros_like(v)
    dv[..., 0] = 1.0
    dv[..., 1:] = np.linalg.solve(jac[..., 1:], -jac[..., :1])[..., 0]
    _, _, quad = _evaluate(loops, v, dv)
    ddv = np.zeros_like(v)
    ddv[..., 1:] = np.linalg.solve(jac[..., 1:], -quad[..., None])[..., 0]
    return Closure(
        v[..., 1],
        dv[..., 1],
        ddv[..., 1],
        {k: v[..., i] for k, i in names.items()},
        {k: dv[..., i] for k, i in names.items()},
        {k: ddv[..., i] for k, i in names.items()},
        closes,
    )

"""Loop closure of any chain in closed form: joint angle q <-> actuator length s, ratios, body angles.

Every quantity is expressed in the frame of the driven joint's parent link P (planar: x, y).
The hinge is at ``h`` with joint-frame angle ``phi``; a point ``c`` of the driven link is at
``C(q) = h + Rz(phi + q) c``, so ``C' = J (C - h)`` and ``C'' = -(C - h)`` (J: +90 deg turn);
primes are derivatives with respect to the joint coordinate q.

* ``triangle`` (seed eqs. qus, k1_3): the actuator joins a point fixed in P and a point of the
  driven link (either pivot may be the moving one). With ``v = end - base``, s = |v|,
  s' = v.v'/s, s'' = (v.v'' + |v'|^2 - s'^2)/s.
* ``linkage``: the pin H is the intersection of the circles |H - r| = l_r (rocker on P) and
  |H - C(q)| = l_c (coupler to the driven link) on the side ``pin_side`` of r -> C. Its
  derivatives follow from differentiating the two circle equations:
  A H' = (0, (H - C).C'),  A H'' = (-|H'|^2, (H - C).C'' - |H' - C'|^2),  A = [(H - r); (H - C)],
  and s = |H - b| as for the triangle with v = H - b.
* ``direct``: s = x0 + q (x0 = 0 when the actuator has no retracted length), s' = 1, s'' = 0.

The stroke is x = s - x0 (x0 = Lc0 + Lc). Joint velocity and acceleration map through
dx = s' dq, ddx = s'' dq^2 + s' ddq (the seed's eqs. dq__ and 04 with k1 = 1/s').
Everything is vectorised over samples (any array shape); SI units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Chain, Machine


@dataclass(frozen=True)
class ChainGeometry:
    """A chain's pivots in the frame of the driven joint's parent P (see the module docstring).

    ``fixed``: role -> (x, y) of pivots fixed in P; ``moving``: role -> (x, y) in the driven
    link's frame; ``hinge``: (x, y) of the hinge in P; ``phi``: joint-frame angle in P [rad].
    """

    kind: str
    hinge: Array
    phi: float
    fixed: dict[str, Array]
    moving: dict[str, Array]
    x0: float
    rocker_length: float = 0.0
    coupler_length: float = 0.0
    pin_side: int = 1


def chain_geometry(machine: Machine, chain: Chain) -> ChainGeometry:
    """Collect the chain's planar geometry from the machine description."""
    link = machine.joint_link(chain.joint)
    rotation = np.asarray(link.joint_frame.rotation)
    fixed: dict[str, Array] = {}
    moving: dict[str, Array] = {}
    for pivot in chain.pivots:
        (moving if pivot.link == link.name else fixed)[pivot.role] = pivot.xy
    x0 = chain.actuator.retracted_length
    linkage = chain.linkage
    return ChainGeometry(
        kind=chain.kind,
        hinge=np.asarray(link.joint_frame.position[:2], dtype=float),
        phi=float(np.arctan2(rotation[1, 0], rotation[0, 0])),
        fixed=fixed,
        moving=moving,
        x0=0.0 if x0 is None else x0,
        rocker_length=0.0 if linkage is None else linkage.rocker_length,
        coupler_length=0.0 if linkage is None else linkage.coupler_length,
        pin_side=1 if linkage is None else linkage.pin_side,
    )


@dataclass(frozen=True)
class Closure:
    """Loop closure of one chain at joint samples q: every array has the shape of q.

    ``length``, ``length_dq``, ``length_dq2``: s [m], ds/dq, d2s/dq2 (per rad or per m).
    ``angles`` (and ``_dq``, ``_dq2``): in-plane angle in the frame P of the x axis of each
    dependent body: ``cylinder`` (base pivot -> end), and for a linkage ``rocker`` (r -> H) and
    ``coupler`` (H -> coupler pivot) [rad]. ``closes``: False where the loop cannot be assembled
    (the other fields are NaN there).
    """

    length: Array
    length_dq: Array
    length_dq2: Array
    angles: dict[str, Array]
    angles_dq: dict[str, Array]
    angles_dq2: dict[str, Array]
    closes: NDArray[np.bool_]


def _cross(a: Array, b: Array) -> Array:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _dot(a: Array, b: Array) -> Array:
    return np.einsum("...i,...i->...", a, b)


def _turn(a: Array) -> Array:
    """J a: a turned +90 degrees."""
    return np.stack([-a[..., 1], a[..., 0]], axis=-1)


def _moving_point(geo: ChainGeometry, local: Array, q: Array) -> tuple[Array, Array, Array]:
    """C, C', C'' in P of a point ``local`` of the driven link."""
    angle = geo.phi + q
    c, s = np.cos(angle), np.sin(angle)
    arm = np.stack([c * local[0] - s * local[1], s * local[0] + c * local[1]], axis=-1)
    return geo.hinge + arm, _turn(arm), -arm


def _direction(v: Array, dv: Array, ddv: Array) -> tuple[Array, Array, Array, Array, Array, Array]:
    """Length and angle of v and their first two derivatives."""
    n2 = _dot(v, v)
    n = np.sqrt(n2)
    dn = _dot(v, dv) / n
    ddn = (_dot(v, ddv) + _dot(dv, dv) - dn**2) / n
    angle = np.arctan2(v[..., 1], v[..., 0])
    cr = _cross(v, dv)
    d_angle = cr / n2
    dd_angle = _cross(v, ddv) / n2 - 2.0 * cr * _dot(v, dv) / n2**2
    return n, dn, ddn, angle, d_angle, dd_angle


def closure(machine: Machine, chain: Chain, q: ArrayLike) -> Closure:
    """Closed-form loop closure of ``chain`` at joint samples ``q`` (see the module docstring)."""
    return geometry_closure(chain_geometry(machine, chain), q)


def geometry_closure(geo: ChainGeometry, q: ArrayLike) -> Closure:
    """Closed-form loop closure from a :class:`ChainGeometry`."""
    q = np.asarray(q, dtype=float)
    if geo.kind == "direct":
        zero = np.zeros_like(q)
        return Closure(geo.x0 + q, np.ones_like(q), zero, {}, {}, {}, np.ones(q.shape, dtype=bool))
    if geo.kind == "triangle":
        return _triangle(geo, q)
    with np.errstate(divide="ignore", invalid="ignore"):  # NaN where the loop does not close (closes False)
        return _linkage(geo, q)


@dataclass(frozen=True)
class LengthRate:
    """A chain's length s and ds/dq at joint samples q (the shape of q); a linkage's pin H and coupler pivot C."""

    length: Array
    length_dq: Array
    pin: Array | None = None
    coupler_pivot: Array | None = None


def length_and_rate(geo: ChainGeometry, q: ArrayLike) -> LengthRate:
    """The length s and s' alone, by the same operations as :func:`geometry_closure` (the same numbers, bit for bit).

    For the stroke rows and their design partials, which ask for nothing else: no second derivatives,
    no body angles.
    """
    q = np.asarray(q, dtype=float)
    if geo.kind == "direct":
        return LengthRate(geo.x0 + q, np.ones_like(q))
    if geo.kind == "triangle":
        base, dbase, _ = _point(geo, "base", q)
        end, dend, _ = _point(geo, "end", q)
        v, dv = end - base, dend - dbase
        s = np.sqrt(_dot(v, v))
        return LengthRate(s, _dot(v, dv) / s)
    with np.errstate(divide="ignore", invalid="ignore"):  # as geometry_closure's four-bar
        H, C, _, _, _, _, dH, _ = _pin_and_rate(geo, q)
        v = H - geo.fixed["base"]
        s = np.sqrt(_dot(v, v))
        return LengthRate(s, _dot(v, dH) / s, H, C)


def _point(geo: ChainGeometry, role: str, q: Array) -> tuple[Array, Array, Array]:
    if role in geo.fixed:
        p = np.broadcast_to(geo.fixed[role], (*q.shape, 2))
        zero = np.zeros((*q.shape, 2))
        return p, zero, zero
    return _moving_point(geo, geo.moving[role], q)


def _triangle(geo: ChainGeometry, q: Array) -> Closure:
    base, dbase, ddbase = _point(geo, "base", q)
    end, dend, ddend = _point(geo, "end", q)
    s, ds, dds, a, da, dda = _direction(end - base, dend - dbase, ddend - ddbase)
    closes = s > 0.0
    return Closure(s, ds, dds, {"cylinder": a}, {"cylinder": da}, {"cylinder": dda}, closes)


def pin_position(geo: ChainGeometry, q: Array) -> tuple[Array, Array, Array, NDArray[np.bool_]]:
    """Pin H of a linkage at q: (H, C, u, closes) with C the coupler pivot and u = C - r."""
    r = geo.fixed["rocker"]
    C, _, _ = _moving_point(geo, geo.moving["coupler"], q)
    u = C - r
    d = np.sqrt(_dot(u, u))
    a = (geo.rocker_length**2 - geo.coupler_length**2 + d**2) / (2.0 * d)
    h2 = geo.rocker_length**2 - a**2
    closes = h2 > 0.0
    height = np.sqrt(np.where(closes, h2, 0.0))
    unit = u / d[..., None]
    H = r + a[..., None] * unit + (geo.pin_side * height)[..., None] * _turn(unit)
    return H, C, u, closes


def _solve2(rows_a: Array, rows_b: Array, rhs_a: Array, rhs_b: Array) -> Array:
    """Solve [rows_a; rows_b] X = [rhs_a; rhs_b] for 2-vectors X (Cramer's rule, vectorised)."""
    det = _cross(rows_a, rows_b)
    x = (rhs_a * rows_b[..., 1] - rhs_b * rows_a[..., 1]) / det
    y = (rows_a[..., 0] * rhs_b - rows_b[..., 0] * rhs_a) / det
    return np.stack([x, y], axis=-1)


def _pin_and_rate(
    geo: ChainGeometry, q: Array
) -> tuple[Array, Array, Array, Array, Array, Array, Array, NDArray[np.bool_]]:
    """A four-bar's pin H, coupler pivot C, C', C'', H - r, H - C and H' at q, and where it closes."""
    H, C, _, closes = pin_position(geo, q)
    _, dC, ddC = _moving_point(geo, geo.moving["coupler"], q)
    hr, hc = H - geo.fixed["rocker"], H - C
    dH = _solve2(hr, hc, np.zeros(q.shape), _dot(hc, dC))
    return H, C, dC, ddC, hr, hc, dH, closes


def _linkage(geo: ChainGeometry, q: Array) -> Closure:
    b = geo.fixed["base"]
    H, C, dC, ddC, hr, hc, dH, closes = _pin_and_rate(geo, q)
    ddH = _solve2(hr, hc, -_dot(dH, dH), _dot(hc, ddC) - _dot(dH - dC, dH - dC))
    s, ds, dds, a_cyl, da_cyl, dda_cyl = _direction(H - b, dH, ddH)
    _, _, _, a_r, da_r, dda_r = _direction(hr, dH, ddH)
    _, _, _, a_c, da_c, dda_c = _direction(C - H, dC - dH, ddC - ddH)
    return Closure(
        s,
        ds,
        dds,
        {"cylinder": a_cyl, "rocker": a_r, "coupler": a_c},
        {"cylinder": da_cyl, "rocker": da_r, "coupler": da_c},
        {"cylinder": dda_cyl, "rocker": dda_r, "coupler": dda_c},
        closes,
    )


# ---------------------------------------------------------------------------------------------
# Joint <-> actuator
# ---------------------------------------------------------------------------------------------


def joint_to_stroke(machine: Machine, chain: Chain, q: ArrayLike) -> Array:
    """Actuator stroke x = s(q) - x0 at joint samples q [m]."""
    geo = chain_geometry(machine, chain)
    return length_and_rate(geo, q).length - geo.x0


def joint_to_actuator(
    machine: Machine, chain: Chain, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike
) -> tuple[Array, Array, Array]:
    """Actuator stroke, velocity, acceleration (x, dx, ddx) from the joint's: dx = s' dq, ddx = s'' dq^2 + s' ddq."""
    geo = chain_geometry(machine, chain)
    c = geometry_closure(geo, q)
    dq, ddq = np.asarray(dq, dtype=float), np.asarray(ddq, dtype=float)
    return c.length - geo.x0, c.length_dq * dq, c.length_dq2 * dq**2 + c.length_dq * ddq


def actuator_to_joint(
    machine: Machine, chain: Chain, x: ArrayLike, dx: ArrayLike, ddx: ArrayLike
) -> tuple[Array, Array, Array]:
    """Joint coordinate, velocity, acceleration (q, dq, ddq) from the actuator's (inverts :func:`joint_to_actuator`)."""
    q = stroke_to_joint(machine, chain, x)
    c = closure(machine, chain, q)
    dq = np.asarray(dx, dtype=float) / c.length_dq
    return q, dq, (np.asarray(ddx, dtype=float) - c.length_dq2 * dq**2) / c.length_dq


def _branch_reference(machine: Machine, chain: Chain) -> float:
    low, high = machine.joint_link(chain.joint).joint_range or (0.0, 0.0)
    return 0.5 * (low + high)


def _circle_intersection(centre_a: Array, radius_a: Array, centre_b: Array, radius_b: Array, side: Array) -> Array:
    """Intersection of two circles on the side ``side`` (+1: left of a -> b)."""
    u = centre_b - centre_a
    d = np.sqrt(_dot(u, u))
    a = (radius_a**2 - radius_b**2 + d**2) / (2.0 * d)
    h2 = radius_a**2 - a**2
    if np.any(~(h2 >= 0.0)):
        raise InvalidInputError("stroke", "outside the loop's assembly range", "the loop does not close there", "m")
    unit = u / d[..., None]
    return centre_a + a[..., None] * unit + (side * np.sqrt(h2))[..., None] * _turn(unit)


def stroke_to_joint(machine: Machine, chain: Chain, x: ArrayLike) -> Array:
    """Joint coordinate q for actuator stroke x (closed-form inverse, branch of the working range).

    The assembly branch (which side of each circle intersection) is the one the chain has at the
    middle of its joint working range; the angle is unwrapped to lie within pi of that middle.
    """
    geo = chain_geometry(machine, chain)
    s = np.asarray(x, dtype=float) + geo.x0
    if geo.kind == "direct":
        return s - geo.x0
    q_ref = _branch_reference(machine, chain)
    if geo.kind == "triangle":
        role = "end" if "end" in geo.moving else "base"
        fixed = geo.fixed["base" if role == "end" else "end"]
        local = geo.moving[role]
        ref_point, _, _ = _moving_point(geo, local, np.array(q_ref))
        side = np.sign(_cross(ref_point - geo.hinge, fixed - geo.hinge))
        point = _circle_intersection(geo.hinge, np.full(s.shape, np.linalg.norm(local)), fixed, s, -side)
    else:
        r, b = geo.fixed["rocker"], geo.fixed["base"]
        H_ref, C_ref, _, _ = pin_position(geo, np.array(q_ref))
        side_h = np.sign(_cross(r - b, H_ref - b))
        H = _circle_intersection(b, s, r, np.full(s.shape, geo.rocker_length), side_h)
        local = geo.moving["coupler"]
        side_c = np.sign(_cross(H_ref - geo.hinge, C_ref - geo.hinge))
        point = _circle_intersection(
            geo.hinge, np.full(s.shape, np.linalg.norm(local)), H, np.full(s.shape, geo.coupler_length), side_c
        )
    arm = point - geo.hinge
    q = np.arctan2(arm[..., 1], arm[..., 0]) - np.arctan2(local[1], local[0]) - geo.phi
    return q - 2.0 * np.pi * np.round((q - q_ref) / (2.0 * np.pi))

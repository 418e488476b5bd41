"""Mounting space of the cylinder pivots: polygons and clearances as smooth constraints of Xi [m].

Pivot positions. The boom hinges and booms do not depend on the link lengths (see
:class:`~hiab_sim.config.ClosedChain`): of a chain's three pins only the cylinder base pivot {Bc}
moves with Xi, along the fixed base axis a of its parent link,

    p(L) = h - L a,        dp/dL = -a,        dp/dLc0 = dp/dLc = 0,

with h the boom hinge {B1}. The rod-end pivot {Tc} is fixed on the boom at (L1, 0) in the boom
frame; in the parent frame it turns with the joint, h + Rz(base_axis_angle + theta -
joint_offset) (L1, 0), and is independent of Xi. Every constraint here is a function of the two
L's only; a polygon row is even linear in Xi, so its first-order tolerance margin is exact.

Mounting polygons. Optional convex polygons, the lift cylinder's base pivot's in the base frame
{W}, the tilt cylinder's in the lift boom frame {B11}, list where a pivot bracket can be welded.
For a counter-clockwise polygon with vertices v_i and edges e_i = v_{i+1} - v_i, the inward unit
normal is n_i = (-e_iy, e_ix) / |e_i| and the row

    g_i(Xi) = n_i . (p(L) - v_i) >= 0,        dg_i/dL = -n_i . a,

is the signed distance of the pivot to the line of edge i (>= 0 on the inner side of every edge
is inside the polygon).

Clearances (the model). A pin has a finite eye: each base pivot must keep ``clearance`` [m]
(centre to centre) from

- every other pin on its parent link (base: the lift boom hinge; lift boom: its hinge to the
  base, the lift cylinder's rod-end pin {Tc1} and the tilt boom hinge), rows |p - c| - clearance;
- the centre line of the boom its chain drives, over the whole working range of the joint: the
  boom is the polyline hinge -> rod-end pivot -> next hinge ({B11}: (0, 0) -> (L11, 0) -> tilt
  hinge; {B12}: (0, 0) -> (L21, 0) -> telescope cylinder frame {P22}), turned by the joint angle
  sampled at ``samples`` points of its working range; the row is the smallest point-to-segment
  distance minus ``clearance``.

The distance rows are piecewise smooth: their gradient d|p - c|/dL = -(p - c) . a / |p - c|
(c the closest point, fixed to first order) is exact wherever the closest sample and segment are
unique. Base outline: the lift pivot sits on the base; staying inside its polygon is what keeps
it on the base, so the base outline is the lift polygon.

Default example (:func:`built_space`): the built crane's space, a rectangle on each pivot's
path, centred at the built pivot, +-0.10 m along the path (the base axis) and +-0.05 m across.
These are our assumption for the size of a pivot bracket, not a drawing of the XS 031: they
leave the built crane 0.10 m of travel either way (so a 1 mm tolerance is far from binding) and
stop the pivot from moving past the base's foot or along the lift boom onto another pin.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import ClosedChain, Crane, LinkLengths
from hiab_sim.crane.names import CHAIN_NAMES, LIFT, TILT, boom_link
from hiab_sim.machine.mounting_geometry import (
    DEFAULT_CLEARANCE,
    DEFAULT_SAMPLES,
    Margins,
    Polygon,
    check_clearance_and_samples,
    check_polygon,
    edge_rows,
    margins,
    point_distance,
    polyline_distance,
    read_polygon,
    read_samples,
)
from hiab_sim.yaml_fields import mapping, positive

#: Index of each chain's L in Xi = [L, Lc0, Lc (lift), L, Lc0, Lc (tilt)].
L_INDEX = {LIFT: 0, TILT: 3}


@dataclass(frozen=True)
class MountingSpace:
    """Where the cylinder base pivots may sit: optional convex polygons and a pin clearance.

    Attributes:
        lift: Polygon (counter-clockwise (x, y) vertices [m]) in the base frame {W} for the lift
            cylinder's base pivot, or None (no polygon).
        tilt: Polygon in the lift boom frame {B11} for the tilt cylinder's base pivot, or None.
        clearance: Minimum centre-to-centre distance of a base pivot from other pins and from the
            centre line of the boom it drives [m] (> 0).
        samples: Joint samples over the working range for the boom clearance (>= 2).

    """

    lift: Polygon | None = None
    tilt: Polygon | None = None
    clearance: float = DEFAULT_CLEARANCE
    samples: int = DEFAULT_SAMPLES

    def __post_init__(self) -> None:
        for name in CHAIN_NAMES:
            polygon = getattr(self, name)
            if polygon is not None:
                check_polygon(f"mounting.{name}", polygon)
        check_clearance_and_samples("mounting", self.clearance, self.samples)

    def polygon(self, chain: str) -> Polygon | None:
        """The polygon of a chain's base pivot (``lift`` or ``tilt``), or None."""
        return self.lift if chain == LIFT else self.tilt

    @classmethod
    def from_mapping(cls, data: Any, where: str = "mounting") -> MountingSpace:
        """Build from a study's ``mounting`` mapping.

        Example (the built XS 031 space of :func:`built_space`, rounded)::

            mounting:
              lift: [[0.269, -0.159], [0.194, 0.026], [0.101, -0.011], [0.176, -0.196]]  # base frame {W}, m
              tilt: [[0.390, -0.054], [0.584, -0.006], [0.559, 0.091], [0.365, 0.043]]   # lift boom frame {B11}, m
              clearance: 0.05                                                              # m
        """
        node = mapping(data, where, {LIFT, TILT, "clearance", "samples"}, required=set())
        polygons = {name: read_polygon(node.get(name), f"{where}.{name}") for name in CHAIN_NAMES}
        clearance = positive(node.get("clearance", DEFAULT_CLEARANCE), f"{where}.clearance", "m")
        samples = read_samples(node.get("samples"), f"{where}.samples")
        return cls(lift=polygons[LIFT], tilt=polygons[TILT], clearance=clearance, samples=samples)


def built_space(crane: Crane, along: float = 0.10, across: float = 0.05) -> MountingSpace:
    """The built crane's space: per chain a rectangle on the pivot's path around the built pivot.

    The rectangle is centred at the built base pivot, +-``along`` [m] along the base axis (the
    pivot's path as L changes) and +-``across`` [m] perpendicular to it, counter-clockwise.
    """
    polygons: dict[str, Polygon] = {}
    for chain in crane.chains:
        centre = chain.base_pivot(chain.default_lengths)[:2]
        a = chain.base_axis[:2]
        n = np.array([-a[1], a[0]])
        corners = [centre + sa * along * a + sn * across * n for sa, sn in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        polygons[chain.name] = tuple((float(c[0]), float(c[1])) for c in corners)
    return MountingSpace(lift=polygons[LIFT], tilt=polygons[TILT])


def base_pivot(chain: ClosedChain, lengths: LinkLengths) -> tuple[Array, Array]:
    """Cylinder base pivot (x, y) in the parent frame [m] and its Jacobian d/dXi (2, 6)."""
    xi = getattr(lengths, chain.name)
    jacobian = np.zeros((2, 6))
    jacobian[:, L_INDEX[chain.name]] = -chain.base_axis[:2]
    return chain.base_pivot(xi)[:2], jacobian


def rod_end_pivot(chain: ClosedChain, theta: Any) -> Array:
    """Rod-end pivot {Tc} (x, y) in the parent frame for joint angles theta, (..., 2) [m]; no Xi dependence."""
    return _boom_points(chain, np.asarray(theta, dtype=float), np.array([[chain.L1, 0.0]]))[..., 0, :]


def _boom_points(chain: ClosedChain, theta: Array, local: Array) -> Array:
    """Points given in the boom frame, in the parent frame: (..., P, 2) [m]."""
    angle = chain.base_axis_angle + theta - chain.joint_offset
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    x, y = local[:, 0], local[:, 1]
    return np.stack([chain.boom_hinge[0] + c * x - s * y, chain.boom_hinge[1] + s * x + c * y], axis=-1)


def boom_centre_line(crane: Crane, chain: ClosedChain) -> Array:
    """Vertices (P, 2) of the centre line of the boom a chain drives, in the boom frame [m].

    Hinge (0, 0) -> rod-end pivot (L1, 0) -> the next link's origin on this boom: the tilt hinge
    for the lift boom, the telescope cylinder frame {P22} for the tilt boom.
    """
    # the tilt chain's parent is the lift boom: its boom_hinge is given in {B11} already
    tip = crane.tilt.boom_hinge if chain.name == LIFT else np.asarray(crane.telescope.cylinder_frame.position)
    return np.array([[0.0, 0.0], [chain.L1, 0.0], [float(tip[0]), float(tip[1])]])


def parent_pins(crane: Crane, chain: ClosedChain) -> dict[str, Array]:
    """Pins fixed on a chain's parent link (parent frame, [m]) other than this chain's base pivot and hinge."""
    pins: dict[str, Array] = {}
    for other in crane.chains:
        if other.parent == chain.parent and other is not chain:
            pins[f"{other.name} boom hinge"] = other.boom_hinge[:2]
        if boom_link(other.name) == chain.parent:
            pins[f"{other.name} boom hinge"] = np.zeros(2)
            pins[f"{other.name} rod-end pivot"] = np.array([other.L1, 0.0])
    return pins


def polygon_margins(space: MountingSpace, crane: Crane, lengths: LinkLengths) -> Margins:
    """Signed distances [m] of each base pivot to the edges of its polygon (>= 0 inside), exact dg/dXi."""
    names: list[str] = []
    values: list[float] = []
    rows: list[Array] = []
    for chain in crane.chains:
        polygon = space.polygon(chain.name)
        if polygon is None:
            continue
        p, dp = base_pivot(chain, lengths)
        edge_values, edge_jacobian = edge_rows(polygon, p, dp)
        names += [f"mounting.{chain.name} base pivot inside edge {i}" for i in range(len(polygon))]
        values += edge_values
        rows += edge_jacobian
    return margins(names, values, rows, 6)


def clearance_margins(space: MountingSpace, crane: Crane, lengths: LinkLengths) -> Margins:
    """Clearance of each base pivot from the other pins on its link and from its swept boom [m], dg/dXi."""
    names: list[str] = []
    values: list[float] = []
    rows: list[Array] = []
    for chain in crane.chains:
        p, dp = base_pivot(chain, lengths)
        for label, pin in parent_pins(crane, chain).items():
            d, grad = point_distance(p, pin)
            names.append(f"mounting.{chain.name} base pivot clear of the {label}")
            values.append(d - space.clearance)
            rows.append(grad @ dp)
        theta = np.linspace(*chain.joint_range, space.samples)
        line = _boom_points(chain, theta, boom_centre_line(crane, chain))  # (S, P, 2)
        d, grad, _, _ = polyline_distance(p, line)
        names.append(f"mounting.{chain.name} base pivot clear of the {chain.name} boom over its working range")
        values.append(d - space.clearance)
        rows.append(grad @ dp)
    return margins(names, values, rows, 6)


def mounting_margins(space: MountingSpace, crane: Crane, lengths: LinkLengths) -> Margins:
    """All mounting rows: the polygons (if given) then the clearances."""
    return Margins.stacked([polygon_margins(space, crane, lengths), clearance_margins(space, crane, lengths)], 6)


__all__ = [
    "Margins",
    "MountingSpace",
    "base_pivot",
    "boom_centre_line",
    "built_space",
    "clearance_margins",
    "mounting_margins",
    "parent_pins",
    "polygon_margins",
    "rod_end_pivot",
]

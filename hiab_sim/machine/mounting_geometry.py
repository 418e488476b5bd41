"""Planar geometry of a mounting space: convex polygons, their edge rows, point and swept-polyline distances [m].

The rows a mounting space adds to a design are margins g >= 0 of the decision variables with an
exact Jacobian (:class:`Margins`); a pin position p and its Jacobian dp/dXi (2, n) go in.

Polygon rows. For a counter-clockwise convex polygon with vertices v_i and edges e_i = v_{i+1} - v_i,
the inward unit normal is n_i = (-e_iy, e_ix) / |e_i| and the row

    g_i = n_i . (p - v_i) >= 0,        dg_i/dXi = n_i . dp/dXi,

is the signed distance of p to the line of edge i (>= 0 on the inner side of every edge is inside).

Distance rows. |p - c| and the smallest distance from p to the segments of polylines; their
gradient (p - c) / |p - c| (c the closest point, fixed to first order) is exact wherever the
closest sample and segment are unique: the rows are piecewise smooth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.yaml_fields import number

Polygon = tuple[tuple[float, float], ...]

#: Default centre-to-centre clearance of two pins [m]: two 25 mm pin eyes (our assumption).
DEFAULT_CLEARANCE = 0.05
#: Default number of joint samples over the working range for the swept-link clearance.
DEFAULT_SAMPLES = 91


def check_polygon(field: str, vertices: Polygon) -> None:
    """Raise unless ``vertices`` is a strictly convex, counter-clockwise polygon of finite points."""
    if len(vertices) < 3:
        raise InvalidInputError(field, len(vertices), "a polygon needs at least 3 vertices")
    v = np.asarray(vertices, dtype=float)
    if v.shape != (len(vertices), 2) or not np.all(np.isfinite(v)):
        raise InvalidInputError(field, str(vertices), "vertices must be finite (x, y) pairs", "m")
    edges = np.roll(v, -1, axis=0) - v
    if np.any(np.hypot(edges[:, 0], edges[:, 1]) <= 1e-9):
        raise InvalidInputError(field, str(vertices), "consecutive vertices must differ", "m")
    turns = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
    if np.all(turns < 0.0):
        raise InvalidInputError(field, "clockwise", "vertices must be listed counter-clockwise", "m")
    if not np.all(turns > 0.0):
        raise InvalidInputError(field, str(vertices), "the polygon must be strictly convex (no reflex or flat vertex)")
    winding = np.sum(np.arctan2(turns, np.sum(edges * np.roll(edges, -1, axis=0), axis=1)))
    if not math.isclose(float(winding), 2.0 * math.pi, abs_tol=1e-6):
        raise InvalidInputError(field, str(vertices), "the polygon must not cross itself (winds more than once)")


def check_clearance_and_samples(where: str, clearance: float, samples: int) -> None:
    """Raise unless the clearance is a finite distance > 0 [m] and the samples an integer >= 2."""
    if not (math.isfinite(clearance) and clearance > 0.0):
        raise InvalidInputError(f"{where}.clearance", clearance, "must be a finite distance > 0", "m")
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        raise InvalidInputError(f"{where}.samples", samples, "must be an integer >= 2")


def read_polygon(data: Any, where: str) -> Polygon | None:
    """A polygon from YAML (a list of [x, y] vertices [m]), or None when the key is absent."""
    if data is None:
        return None
    if not isinstance(data, list | tuple):
        raise ConfigError(f"{where}: expected a list of [x, y] vertices, got {data!r}")
    out = []
    for i, vertex in enumerate(data):
        if not isinstance(vertex, list | tuple) or len(vertex) != 2:
            raise ConfigError(f"{where}[{i}]: expected [x, y], got {vertex!r}")
        out.append((number(vertex[0], f"{where}[{i}][0]"), number(vertex[1], f"{where}[{i}][1]")))
    return tuple(out)


def read_samples(data: Any, where: str) -> int:
    """The swept-link samples from YAML (default :data:`DEFAULT_SAMPLES`); the range is checked by the space."""
    samples = DEFAULT_SAMPLES if data is None else data
    if isinstance(samples, bool) or not isinstance(samples, int):
        raise ConfigError(f"{where}: expected an integer, got {samples!r}")
    return samples


@dataclass(frozen=True)
class Margins:
    """Constraint rows g(Xi) >= 0 with their names and exact Jacobian dg/dXi ((m, n_xi), [m/m])."""

    names: tuple[str, ...]
    values: Array
    jacobian: Array

    def worst(self) -> tuple[str, float]:
        """The smallest margin and its name [m] (``("none", inf)`` when there are no rows)."""
        if not self.names:
            return "none", math.inf
        k = int(np.argmin(self.values))
        return self.names[k], float(self.values[k])

    @staticmethod
    def stacked(parts: list[Margins], n: int) -> Margins:
        """The rows of ``parts`` one after the other (n columns when there are none)."""
        names = tuple(name for part in parts for name in part.names)
        values = np.concatenate([part.values for part in parts]) if parts else np.zeros(0)
        jacobian = np.vstack([part.jacobian for part in parts]) if parts else np.zeros((0, n))
        return Margins(names, values, jacobian)


def margins(names: list[str], values: list[float], rows: list[Array], n: int) -> Margins:
    """Rows collected one by one as :class:`Margins` with n columns."""
    return Margins(tuple(names), np.asarray(values, dtype=float), np.asarray(rows, dtype=float).reshape(len(rows), n))


def edge_rows(polygon: Polygon, p: Array, dp: Array) -> tuple[list[float], list[Array]]:
    """Signed distances of p to the polygon's edges (>= 0 inside) [m] and their rows n_i . dp (module docstring)."""
    values: list[float] = []
    rows: list[Array] = []
    v = np.asarray(polygon)
    for i in range(len(v)):
        edge = v[(i + 1) % len(v)] - v[i]
        normal = np.array([-edge[1], edge[0]]) / np.hypot(edge[0], edge[1])
        values.append(float(normal @ (p - v[i])))
        rows.append(normal @ dp)
    return values, rows


def point_distance(p: Array, c: Array) -> tuple[float, Array]:
    """|p - c| [m] and its gradient w.r.t. p."""
    delta = p - c
    d = float(np.hypot(delta[0], delta[1]))
    return d, delta / d


def polyline_distance(p: Array, lines: Array) -> tuple[float, Array, tuple[int, int], float]:
    """Smallest distance [m] from p to the segments of polylines (S, P, 2), its gradient w.r.t. p and where.

    Returns the distance, (p - c) / |p - c| with c the closest point, the (sample, segment) index
    of c and its parameter t in [0, 1] along that segment (c = a + t (b - a)).
    """
    a, b = lines[:, :-1, :], lines[:, 1:, :]
    ab = b - a
    t = np.clip(np.einsum("spk,spk->sp", p - a, ab) / np.einsum("spk,spk->sp", ab, ab), 0.0, 1.0)
    closest = a + t[..., None] * ab
    delta = p - closest
    d = np.hypot(delta[..., 0], delta[..., 1])
    k = np.unravel_index(int(np.argmin(d)), d.shape)
    return float(d[k]), delta[k] / d[k], (int(k[0]), int(k[1])), float(t[k])


__all__ = [
    "DEFAULT_CLEARANCE",
    "DEFAULT_SAMPLES",
    "Margins",
    "Polygon",
    "check_clearance_and_samples",
    "check_polygon",
    "edge_rows",
    "margins",
    "point_distance",
    "polyline_distance",
    "read_polygon",
    "read_samples",
]

"""Manufacturing tolerance: rounding a design and checking every design within +-tolerance [m].

A workshop builds Xi = [L, Lc0, Lc (lift), L, Lc0, Lc (tilt)] to a tolerance t (default 1 mm):
the built design is any Xi' with |Xi'_j - Xi_j| <= t. Two tools here, independent of the NLP:

- :func:`round_lengths` rounds a design to the nearest multiple of t (what a drawing states);
- :func:`check_tolerance` evaluates any margin function g(Xi) >= 0 on the nominal design, the
  rounded design and the 2^6 corners of the box Xi +- t. The corners bound g over the box
  exactly when g is monotone in each Xi_j over the box (linear rows; the stroke rows below,
  whose only nonlinearity is the smooth pin-to-pin length s(L) over 2 t).

Robust NLP rows (for the optimiser, not done here). To keep a row g feasible for every design
in the box, the optimiser imposes the worst-case margin to first order,

    g_rob(Xi) = g(Xi) - sum_j |dg/dXi_j| t_j >= 0                                   (1)

which is exact for rows linear in Xi (|dg/dXi| is then constant and the minimum over the box
sits at the corner sign(dg/dXi) -t). Rows linear in Xi: the bounds on Xi (const_g), Lc - stroke
(const_j), the mounting polygons (:mod:`hiab_sim.crane.mounting`, linear in L), and the stroke
rows in Lc0 and Lc (x = s(L, theta) - Lc0 - Lc, so dx/dLc0 = dx/dLc = -1). Nonlinear: the stroke
rows in L (ds/dL = (L - L1 cos q) / s, curvature d2s/dL2 = (1 - (ds/dL)^2) / s, so (1) errs by
at most t^2 / (2 s) ~ 4e-7 m at t = 1 mm), the pin clearances, and every row that goes through
the dynamics (EMLA envelope, energy). For those (1) is a first-order estimate; the rounded
design must then be re-checked (this module's :func:`check_tolerance`). (1) is non-smooth where
a dg/dXi_j changes sign; an NLP can split it with slack s_j >= +-dg/dXi_j t_j.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane import mechanism
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.mounting import Margins, MountingSpace, mounting_margins
from hiab_sim.errors import InvalidInputError

#: Default manufacturing tolerance of a link length [m].
DEFAULT_TOLERANCE = 1e-3

MarginFunction = Callable[[LinkLengths], Margins]


def _check_tolerance_value(tolerance: float) -> None:
    if not (isinstance(tolerance, int | float) and math.isfinite(tolerance) and tolerance > 0.0):
        raise InvalidInputError("tolerance", tolerance, "must be a finite length > 0", "m")


def round_lengths(lengths: LinkLengths, tolerance: float = DEFAULT_TOLERANCE) -> LinkLengths:
    """The design rounded to the nearest multiple of ``tolerance`` [m] (half away from zero)."""
    _check_tolerance_value(tolerance)
    x = lengths.as_array() / tolerance
    rounded = np.sign(x) * np.floor(np.abs(x) + 0.5) * tolerance
    # print the same decimals a drawing would: kill the binary noise of the multiplication
    digits = max(0, -math.floor(math.log10(tolerance)) + 3)
    return LinkLengths.from_array(np.round(rounded, digits))


def tolerance_designs(lengths: LinkLengths, tolerance: float = DEFAULT_TOLERANCE) -> tuple[tuple[str, ...], Array]:
    """Labels and designs (66, 6) [m]: nominal, rounded, then the 64 corners of Xi +- tolerance.

    A corner's label lists the sign of each offset in Xi order, e.g. ``corner +-+--+``.
    """
    _check_tolerance_value(tolerance)
    nominal = lengths.as_array()
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=6)))
    labels = ("nominal", "rounded", *("corner " + "".join("+" if v > 0 else "-" for v in s) for s in signs))
    designs = np.vstack([nominal, round_lengths(lengths, tolerance).as_array(), nominal + tolerance * signs])
    return labels, designs


@dataclass(frozen=True)
class ToleranceCheck:
    """Margins of every design within tolerance: ``margins[d, r]`` of design ``labels[d]``, row ``names[r]``."""

    tolerance: float
    labels: tuple[str, ...]
    designs: Array
    names: tuple[str, ...]
    margins: Array

    @property
    def ok(self) -> bool:
        """Whether every row holds (>= 0) for every design checked."""
        return bool(np.all(self.margins >= 0.0))

    def worst(self) -> tuple[str, str, float]:
        """(design label, row name, margin) of the smallest margin."""
        d, r = np.unravel_index(int(np.argmin(self.margins)), self.margins.shape)
        return self.labels[d], self.names[r], float(self.margins[d, r])

    def summary(self) -> str:
        """One line: passed, or the worst design and row with its margin."""
        label, name, value = self.worst()
        verdict = "every design within" if self.ok else "NOT every design within"
        return (
            f"{verdict} +-{self.tolerance * 1e3:g} mm holds ({len(self.labels)} designs, {len(self.names)} rows); "
            f"worst: {name} = {value:.3g} at the {label} design"
        )


def check_tolerance(g: MarginFunction, lengths: LinkLengths, tolerance: float = DEFAULT_TOLERANCE) -> ToleranceCheck:
    """Evaluate the margin function ``g`` on every design of :func:`tolerance_designs`."""
    labels, designs = tolerance_designs(lengths, tolerance)
    rows = [g(LinkLengths.from_array(d)) for d in designs]
    return ToleranceCheck(
        tolerance=tolerance,
        labels=labels,
        designs=designs,
        names=rows[0].names,
        margins=np.vstack([r.values for r in rows]),
    )


def robust_margins(margins: Margins, tolerance: float | ArrayLike = DEFAULT_TOLERANCE) -> Array:
    """First-order worst-case margins over Xi +- tolerance, eq. (1) of the module docstring [m].

    ``tolerance`` is one value [m] or one per Xi entry (6,).
    """
    t = np.broadcast_to(np.asarray(tolerance, dtype=float), (6,))
    return np.asarray(margins.values - np.abs(margins.jacobian) @ t, dtype=float)


def working_range_margins(crane: Crane, lengths: LinkLengths) -> Margins:
    """The crane's own length checks (:func:`hiab_sim.crane.mechanism.check_lengths`) as margins [m] with dg/dXi.

    Per chain: L, Lc0, Lc > 0 (const_g); Lc - stroke >= 0 (const_j); at the ends of the working
    range x(theta_low) >= 0 and x(theta_up) <= min(stroke, Lc) (const_j, const_k), with
    x = s - Lc0 - Lc, s^2 = L^2 + L1^2 - 2 L L1 cos q (eq. qus_a), q = joint_offset - pi - theta,
    so dx/dL = (L - L1 cos q) / s and dx/dLc0 = dx/dLc = -1. The margins carry the check's
    round-off slack :data:`~hiab_sim.crane.mechanism.STROKE_TOLERANCE`. The check's other
    condition, q strictly inside (-pi, 0) at the range ends, does not depend on Xi.
    """
    names: list[str] = []
    values: list[float] = []
    rows: list[Array] = []
    slack = mechanism.STROKE_TOLERANCE
    for k, (chain, xi) in enumerate(zip(crane.chains, lengths, strict=True)):
        col = 3 * k
        for j, key in enumerate(("L", "Lc0", "Lc")):
            names.append(f"{chain.name}.{key} > 0")
            values.append(getattr(xi, key))
            rows.append(_unit(col + j))
        names.append(f"{chain.name}.Lc - stroke >= 0")
        values.append(xi.Lc - chain.stroke)
        rows.append(_unit(col + 2))
        q = mechanism.hinge_angle(chain, np.asarray(chain.joint_range))
        s = np.sqrt(xi.L**2 + chain.L1**2 - 2.0 * xi.L * chain.L1 * np.cos(q))
        x = s - xi.x0
        dx = np.zeros((2, 6))
        dx[:, col] = (xi.L - chain.L1 * np.cos(q)) / s
        dx[:, col + 1] = dx[:, col + 2] = -1.0
        names += [f"{chain.name}.x >= 0 at the low end", f"{chain.name}.x <= stroke at the up end"]
        values += [float(x[0]) + slack, chain.stroke - float(x[1]) + slack]
        rows += [dx[0], -dx[1]]
        names.append(f"{chain.name}.x <= Lc at the up end")
        values.append(xi.Lc - float(x[1]) + slack)
        rows.append(_unit(col + 2) - dx[1])
    return Margins(tuple(names), np.asarray(values), np.asarray(rows))


def design_margins(crane: Crane, space: MountingSpace | None = None) -> MarginFunction:
    """g(Xi) for :func:`check_tolerance`: the working-range margins, then (with ``space``) the mounting rows."""

    def g(lengths: LinkLengths) -> Margins:
        wr = working_range_margins(crane, lengths)
        if space is None:
            return wr
        mm = mounting_margins(space, crane, lengths)
        return Margins(
            wr.names + mm.names, np.concatenate([wr.values, mm.values]), np.vstack([wr.jacobian, mm.jacobian])
        )

    return g


def _unit(j: int) -> Array:
    e = np.zeros(6)
    e[j] = 1.0
    return e


#: Default stroke margin at both ends of the working range [m] (see :func:`buildable_crane`): the
#: robust stroke rows use about 3 t of stroke at each end (t = 1 mm), plus 1 mm of room.
DEFAULT_STROKE_MARGIN = 4e-3


def buildable_crane(
    crane: Crane, stroke_margin: float = DEFAULT_STROKE_MARGIN, field: str = "build.stroke_margin"
) -> Crane:
    """The crane with each chain's working joint range shortened by a stroke margin at both ends.

    The new range is the part of the crane's joint range over which its own cylinders (the
    chain's ``default_lengths``) keep ``stroke_margin`` [m] from both stroke ends,
    theta in [theta(x = m), theta(x = stroke - m)] (eqs. qus_a, thetas; theta increases with x),
    intersected with the crane's range. A design served over this range keeps spare stroke
    at both ends that a manufacturing tolerance can use up: x = s(L, theta) - Lc0 - Lc moves by
    up to (|dx/dL| + 2) t at each end for a tolerance t on (L, Lc0, Lc), about 3 t. The XS 031's
    tilt range uses its whole 0.59 m stroke (the ends sit at x = 0 and x = stroke), so without
    a margin no design within +-t of the nominal one serves it. ``stroke_margin = 0`` returns
    the crane unchanged.
    """
    if not (math.isfinite(stroke_margin) and stroke_margin >= 0.0):
        raise InvalidInputError(field, stroke_margin, "must be a finite length >= 0", "m")
    if stroke_margin == 0.0:
        return crane
    chains = {}
    for chain in crane.chains:
        if not 2.0 * stroke_margin < chain.stroke:
            raise InvalidInputError(
                field, stroke_margin, f"must be < half the {chain.name} stroke {chain.stroke:.6g}", "m"
            )
        theta = mechanism.stroke_to_joint(
            chain, chain.default_lengths, np.array([stroke_margin, chain.stroke - stroke_margin])
        )
        lo, hi = chain.joint_range
        new = (max(lo, float(theta[0])), min(hi, float(theta[1])))
        chains[chain.name] = replace(chain, joint_range=new)
    narrowed: dict[str, Any] = {chain.name: chains[chain.name] for chain in crane.chains}  # its fields are named so
    return replace(crane, **narrowed)


def range_cost_deg(crane: Crane, stroke_margin: float = DEFAULT_STROKE_MARGIN) -> dict[str, tuple[float, float]]:
    """Per chain, the joint range [deg] given up at the (low, up) end by :func:`buildable_crane`."""
    narrow = buildable_crane(crane, stroke_margin)
    out = {}
    for full, short in zip(crane.chains, narrow.chains, strict=True):
        out[full.name] = (
            math.degrees(short.joint_range[0] - full.joint_range[0]),
            math.degrees(full.joint_range[1] - short.joint_range[1]),
        )
    return out

"""Buildable designs: the manufacturing-tolerance setting, robust rows of Xi and the rounded design.

A workshop builds Xi = (L, Lc0, Lc (lift), L, Lc0, Lc (tilt)) to a tolerance t (study setting
``build.tolerance``, default 1 mm): the built design is any Xi' with |Xi'_j - Xi_j| <= t. The
optimiser holds every row g(Xi) >= 0 that depends on Xi only (the working range, the mounting
space) for every such design, to first order (:mod:`hiab_sim.crane.tolerance`, eq. (1)):

    g_rob(Xi) = g(Xi) - sum_j |dg/dXi_j| t >= 0,

    dg_rob/dXi_k = dg/dXi_k - sum_j sign(dg/dXi_j) t d2g/(dXi_j dXi_k).

This is exact for rows linear in Xi (mounting polygons, the stroke rows in Lc0 and Lc); for the
stroke rows in L the curvature d2s/dL2 = (1 - (ds/dL)^2) / s makes it err by <= t^2 / (2 s)
~ 4e-7 m. The second derivatives are central differences (step :data:`HESSIAN_STEP`) of the
wrapped block's exact Jacobian. |.| is not smoothed: on the working-range rows every dg/dXi_j
keeps its sign (dx/dL = (L - L1 cos q) / s > 0 for L > L1, dx/dLc0 = dx/dLc = -1) or is
identically 0, and the mounting rows are linear in L.

Rounded design (:func:`rounded_design`): Xi rounded to the nearest multiple of t, moved inward onto
the grid where rounding would leave the bounds. It lies within t / 2 of the optimum, inside the
box the robust rows hold for, so it is feasible by construction; the report re-checks it anyway
(:mod:`hiab_sim.study.report.buildable_section`).

The settings are :class:`hiab_sim.study.spec.build.BuildSettings`. The stroke margin
(``build.stroke_margin``, default 4 mm) shortens the working range the robust
rows are held over (:func:`hiab_sim.crane.tolerance.buildable_crane`); the nominal design still
serves the crane's full range (the ``working_range`` block), so every tool that reads the crane
file accepts the optimum.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import LinkLengths
from hiab_sim.crane.tolerance import round_lengths
from hiab_sim.errors import InvalidInputError
from hiab_sim.results.design_values import with_values
from hiab_sim.study.constraints.blocks import STROKE_SCALE, WorkingRange
from hiab_sim.study.constraints.mounting_rows import MOUNTING_SCALE, MountingRows
from hiab_sim.study.nlp.interface import (
    ConstraintBlock,
    DenseRows,
    Relaxation,
    SamplePartials,
    SampleState,
)

if TYPE_CHECKING:
    from hiab_sim.study.spec.study_file import Study

#: Clearance [m] the robust stroke rows keep beyond their first-order worst case.
ROBUST_CLEARANCE = 1e-6
#: Step of the central differences of a block's Jacobian w.r.t. Xi [m].
HESSIAN_STEP = 1e-5


class _NoPartials(SamplePartials):
    """Partials of a block of Xi only: the inverse dynamics are never asked for."""

    def __init__(self) -> None:
        def fail() -> Array:
            raise AssertionError("a robust block wraps rows of Xi only")

        super().__init__(fail, fail)


class RobustXi(ConstraintBlock):
    """A block of Xi-only rows held for every design within +-tolerance (module docstring).

    Args:
        inner: A block whose rows depend on Xi only (its Jacobian is ``DenseRows(dxi=...)``).
        tolerance: t [m] of every Xi entry.
        name: This block's name (the inner block's rows are renamed to start with it).

    """

    def __init__(self, inner: ConstraintBlock, tolerance: float, name: str) -> None:
        if not (math.isfinite(tolerance) and tolerance > 0.0):
            raise InvalidInputError("build.tolerance", tolerance, "must be a finite length > 0", "m")
        self.inner = inner
        self.tolerance = tolerance
        self.name = name
        prefix = inner.name
        self._names = [name + row[len(prefix) :] for row in inner.row_names()]

    def row_names(self) -> list[str]:
        """The inner rows, renamed ``<name>.<row>``."""
        return list(self._names)

    def _dxi(self, state: SampleState) -> Array:
        jac = self.inner.jacobian(state, _NoPartials())
        if not isinstance(jac, DenseRows) or jac.dxi is None or jac.dq is not None:
            raise TypeError(f"{self.inner.name}: a robust block needs rows of Xi only")
        return np.asarray(jac.dxi, dtype=float)

    def values(self, state: SampleState) -> Array:
        """G - |dg/dXi| t, (m,)."""
        return self.inner.values(state) - np.abs(self._dxi(state)).sum(axis=1) * self.tolerance

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """dg/dXi - sum_j sign(dg/dXi_j) t d2g/(dXi_j dXi), the Hessian by central differences."""
        dxi = self._dxi(state)
        sign = np.sign(dxi)
        xi = state.lengths.as_array()
        out = dxi.copy()
        for k in range(len(xi)):
            step = np.zeros(len(xi))
            step[k] = HESSIAN_STEP
            plus = self._dxi(replace_lengths(state, xi + step))
            minus = self._dxi(replace_lengths(state, xi - step))
            out[:, k] -= self.tolerance * np.sum(sign * (plus - minus), axis=1) / (2.0 * HESSIAN_STEP)
        return DenseRows(dxi=out)

    def clearance(self) -> Array | float:
        """The inner block's clearance."""
        return self.inner.clearance()

    def relaxation(self, values: Array) -> Relaxation:
        """The inner block's units (the robust rows are its rows less a constant-sign term)."""
        return self.inner.relaxation(values)

    def shared_key(self) -> Hashable | None:
        """The inner block's key with this block's name and tolerance (rows of Xi only)."""
        inner = self.inner.shared_key()
        return None if inner is None else (self.name, inner, self.tolerance)


def replace_lengths(state: SampleState, xi: Array) -> SampleState:
    """The same samples with other link lengths (for rows of Xi only)."""
    return SampleState(
        with_values(state.lengths, xi), state.joints, state.tcp, state.actuators, state.power, duty=state.duty
    )


def rounded_values(values: Array, tolerance: float, low: Array, up: Array) -> Array:
    """Design values rounded to the nearest multiple of ``tolerance`` [m] (half away from zero), inside [low, up].

    A rounded value outside a bound moves to the nearest grid point inside it (the bound rounded
    inward), so the design stays within ``tolerance`` of the optimum and inside the bounds; the
    decimals a drawing would print are kept (the binary noise of the multiplication removed).
    """
    digits = max(0, -math.floor(math.log10(tolerance)) + 3)
    x = np.asarray(values, dtype=float) / tolerance
    rounded = np.round(np.sign(x) * np.floor(np.abs(x) + 0.5) * tolerance, digits)
    low_grid = np.ceil(np.asarray(low) / tolerance - 1e-9) * tolerance
    up_grid = np.floor(np.asarray(up) / tolerance + 1e-9) * tolerance
    out: Array = np.round(np.clip(rounded, low_grid, up_grid), digits).astype(float)
    return out


def rounded_design(lengths: LinkLengths, tolerance: float, low: Array, up: Array) -> LinkLengths:
    """Xi rounded to the nearest multiple of ``tolerance`` [m], kept on the grid inside [low, up].

    A rounded value outside a bound moves to the nearest grid point inside it (the bound rounded
    inward), so the design stays within ``tolerance`` of the optimum and inside the bounds.
    """
    xi = round_lengths(lengths, tolerance).as_array()
    low_grid = np.ceil(np.asarray(low) / tolerance - 1e-9) * tolerance
    up_grid = np.floor(np.asarray(up) / tolerance + 1e-9) * tolerance
    digits = max(0, -math.floor(math.log10(tolerance)) + 3)
    return LinkLengths.from_array(np.round(np.clip(xi, low_grid, up_grid), digits))


def buildable_working_range(study: Study, working: Sequence[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    """The working range the robust rows serve: ``working`` within the study machine's buildable range [rad]."""
    short = study.model.buildable_ranges(study.build.stroke_margin)
    return tuple((max(w[0], c[0]), min(w[1], c[1])) for w, c in zip(working, short, strict=True))


def buildable_blocks(study: Study, working: Sequence[tuple[float, float]], tightened: bool) -> list[ConstraintBlock]:
    """The buildable-design blocks in row order (the ``buildable`` entry of the block registry).

    On the optimiser's grid (``tightened``): the stroke rows at the ends of the buildable working
    range and the mounting rows (if the study has ``mounting``), both robust to +-``build.tolerance``.
    For the nominal re-check: the mounting rows as they are (the rounded design's own re-check
    uses a study whose crane has the buildable range, :mod:`hiab_sim.study.report.buildable_section`).
    """
    t = study.build.tolerance
    blocks: list[ConstraintBlock] = []
    if tightened:
        # the clearance covers the first-order error of the robust rows (<= t^2 / (2 s), module docstring)
        wr = WorkingRange(study.model, buildable_working_range(study, working), ROBUST_CLEARANCE / STROKE_SCALE)
        blocks.append(RobustXi(wr, t, "buildable_range"))
    if study.mounting is not None:
        if tightened:
            rows = MountingRows(study, ROBUST_CLEARANCE / MOUNTING_SCALE)
            blocks.append(RobustXi(rows, t, "mounting"))
        else:
            blocks.append(MountingRows(study))
    return blocks

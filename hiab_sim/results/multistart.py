"""The multi-start section of a result: every start's outcome, the distinct optima and the failed starts."""

from __future__ import annotations

from dataclasses import dataclass

from hiab_sim.results.codec import optional
from hiab_sim.results.design_values import DesignValues


@dataclass(frozen=True)
class StartRow:
    """One start of a multi-start run; a failed start has no optimal lengths or cost."""

    start: int
    initial_lengths: DesignValues
    optimal_lengths: DesignValues | None
    cost_W2s: float | None
    success: bool
    message: str
    iterations: int


@dataclass(frozen=True)
class DistinctOptimum:
    """Converged starts whose Xi agree within the tolerance; energy and objective written with more than one start.

    ``objective_value``: the study's objective at the group's first start, exact (unsmoothed) and weighted over
    the tasks' fine grids [:attr:`MultiStart.objective_unit`], the number the optima are ranked by.
    """

    xi: tuple[float, ...]  # [m], the design's decision variables (the crane's lift L, Lc0, Lc, tilt L, Lc0, Lc)
    cost_W2s: float | None
    starts: tuple[int, ...]
    net_electrical_energy_J: float | None = optional()
    objective_value: float | None = optional()


@dataclass(frozen=True)
class FailedStart:
    """A start whose solver failed (no optimum)."""

    start: int
    initial_xi: tuple[float, ...]
    message: str


@dataclass(frozen=True)
class MultiStart:
    """Whether every converged start reached the same Xi within ``tolerance_m``; else the distinct optima."""

    starts: tuple[StartRow, ...]
    tolerance_m: float
    converged_starts: int
    same_optimum: bool
    distinct_optima: tuple[DistinctOptimum, ...]
    failed_starts: tuple[FailedStart, ...]
    objective: str | None = optional()  # the study's objective's name, with its unit below
    objective_unit: str | None = optional()

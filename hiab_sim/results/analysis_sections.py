"""Typed result sections of the analyses: the buildable (rounded) design, the feasibility phase, sensitivities.

They are optional sections of :class:`hiab_sim.results.schema.Result` (absent from older files).
"""

from __future__ import annotations

from dataclasses import dataclass

from hiab_sim.results.codec import optional
from hiab_sim.results.design_values import DesignValues


@dataclass(frozen=True)
class RoundedCheck:
    """A check of the rounded design: the row of least margin, its value and its unit."""

    passed: bool
    worst: str
    margin: float
    unit: str


@dataclass(frozen=True)
class Buildable:
    """The optimum rounded to the manufacturing tolerance, re-checked (:mod:`hiab_sim.study.report.buildable_section`).

    ``range_given_up_deg[chain]`` = (low end, up end) of the joint range given up for the stroke
    margin [deg]; ``crane_check`` is the crane's own length check over the buildable range
    (:func:`hiab_sim.crane.mechanism.check_lengths`); ``tolerance_check`` every design within
    +-tolerance of the optimum (:func:`hiab_sim.crane.tolerance.check_tolerance`, corners of the
    box) on the working-range and mounting rows [m]; ``recheck`` the fine-grid re-check of the
    rounded lengths with the optimal trajectory (scaled rows of the nominal NLP).
    """

    tolerance_m: float
    stroke_margin_m: float
    range_given_up_deg: dict[str, tuple[float, ...]]
    lengths: DesignValues
    crane_check: RoundedCheck
    tolerance_check: RoundedCheck
    recheck: RoundedCheck
    recheck_id_path: str
    recheck_grid_points: int
    net_electrical_energy_J: float
    drawn_energy_summed_drives_J: float
    net_energy_change_vs_optimum_J: float
    mjcf_command: str


@dataclass(frozen=True)
class FeasibilityPhase:
    """What the feasibility phase did to a start that violated constraints.

    See :mod:`hiab_sim.study.solvers.feasibility`.
    """

    start: int
    initial_max_violation: float
    initial_worst: str
    final_max_violation: float
    lengths_before: DesignValues
    lengths_after: DesignValues
    changes: tuple[str, ...]
    iterations: int


@dataclass(frozen=True)
class Multiplier:
    """One active constraint's multiplier in physical units.

    ``multiplier`` is d(scaled objective)/d(scaled row) >= 0; ``objective_decrease_per_unit`` the
    objective's decrease [the section's ``objective_unit``: W^2 s for costf2, J for battery_energy]
    when the limit is relaxed by one ``unit`` (e.g. ``mm`` of a length bound, ``%`` of an EMLA
    limit); ``percent_per_unit`` the same as a percentage of the objective at the optimum.
    """

    constraint: str
    multiplier: float
    unit: str
    objective_decrease_per_unit: float
    percent_per_unit: float
    rows: int


@dataclass(frozen=True)
class Sensitivity:
    """KKT multipliers of the active constraints at the optimum (:mod:`hiab_sim.study.analysis.sensitivity`).

    ``kkt_residual`` = |grad f - J_A^T lambda| / |grad f| of the non-negative least-squares fit;
    ``objective_value`` the objective at the optimum [``objective_unit``] (the weighted sum over the tasks).
    """

    objective: str
    objective_unit: str
    objective_value: float
    active_tolerance: float
    kkt_residual: float
    multipliers: tuple[Multiplier, ...]


@dataclass(frozen=True)
class CrossEvaluation:
    """The price of robustness: designs x tasks, trajectories re-optimised at fixed Xi.

    See :mod:`hiab_sim.study.analysis.cross_evaluation`.

    Rows are the designs (each task's optimum alone, then the mix optimum), columns the tasks; the
    ``mix_*`` entries are the weighted sums over the tasks; None where a design cannot serve a task.
    Energies [J] on each task's fine grid (nominal bands, the optimisation's ID path), costs of eq.
    ``costf2`` [W^2 s] on the collocation grid whatever the objective, and the study's ``objective``
    [``objective_unit``] on the collocation grid (what the optimiser minimises).
    """

    note: str
    tasks: tuple[str, ...]
    weights: tuple[float, ...]
    designs: tuple[str, ...]
    lengths: tuple[DesignValues, ...]
    net_energy_J: tuple[tuple[float | None, ...], ...]
    drawn_energy_J: tuple[tuple[float | None, ...], ...]
    cost_W2s: tuple[tuple[float | None, ...], ...]
    max_violation: tuple[tuple[float | None, ...], ...]
    mix_net_energy_J: tuple[float | None, ...]
    mix_cost_W2s: tuple[float | None, ...]
    mix_energy_lost_J: tuple[float | None, ...]
    mix_energy_lost_percent: tuple[float | None, ...]
    mix_cost_lost_percent: tuple[float | None, ...]
    #: Per design and task, why the cell is None ("" where it is computed); absent in older files.
    unserved: tuple[tuple[str, ...], ...] = ()
    objective: str | None = optional()
    objective_unit: str | None = optional()
    objective_value: tuple[tuple[float | None, ...], ...] | None = optional()
    mix_objective_value: tuple[float | None, ...] | None = optional()

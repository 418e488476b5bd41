"""A study's sections from its tasks' sections: energies and costs weighted, peaks and violations the worst.

Each task is reported as :func:`hiab_sim.study.report.design_check.design_summary` gives it (its fine
grid, nominal bands, re-checked with the other ID path). The study's ``initial``/``optimal``/
``recheck``/``decomposition`` weigh the tasks' energies and costs by the tasks' weights (per unit
of the weights, e.g. per hour for cycles per hour) and take the worst peaks and violations, worst
constraints named ``<task>: <row>``. A study of one task of weight 1 is its task: every function
returns that task's own section unchanged.
"""

from __future__ import annotations

from collections.abc import Sequence

from hiab_sim.arrays import Array
from hiab_sim.results.schema import (
    ENERGY_PARTS,
    ActuatorSummary,
    Decomposition,
    DecompositionDesign,
    DesignSummary,
    EnergyBreakdown,
    Recheck,
    TrackingError,
    WorstConstraint,
)

TELESCOPE = "prescribed by the reference (third tracked coordinate xt2)"


def is_one_task(weights: list[float]) -> bool:
    """A study of one task of weight 1: its sections are the task's own."""
    return len(weights) == 1 and weights[0] == 1.0


def worst_tracking(errors: Sequence[TrackingError]) -> TrackingError:
    """The largest of each tracking error over the tasks (None where every task has none)."""

    def worst(values: list[float | None]) -> float | None:
        given = [v for v in values if v is not None]
        return max(given) if given else None

    tracked: dict[str, float] = {}
    for e in errors:
        for key, value in (e.tracked or {}).items():
            tracked[key] = max(tracked.get(key, value), value)
    return TrackingError(
        position_m=max(e.position_m for e in errors),
        velocity_m_per_s=max(e.velocity_m_per_s for e in errors),
        acceleration_m_per_s2=max(e.acceleration_m_per_s2 for e in errors),
        telescope_m=worst([e.telescope_m for e in errors]),
        tracked=tracked or None,
    )


def weighted_summary(summaries: list[DesignSummary], weights: Array, names: list[str]) -> DesignSummary:
    """The study's summary: energies and costs weighted, peaks and violations the worst over the tasks."""
    w = [float(v) for v in weights]
    if is_one_task(w):
        return summaries[0]

    def total(values: list[float]) -> float:
        return float(sum(wk * v for wk, v in zip(w, values, strict=True)))

    actuators = {}
    for name in summaries[0].actuators:
        parts = [s.actuators[name] for s in summaries]
        actuators[name] = ActuatorSummary(
            peak_force_N=max(a.peak_force_N for a in parts),
            peak_velocity_m_per_s=max(a.peak_velocity_m_per_s for a in parts),
            peak_electrical_power_W=max(a.peak_electrical_power_W for a in parts),
            min_envelope_margin=min(a.min_envelope_margin for a in parts),
            net_energy_J=total([a.net_energy_J for a in parts]),
            drawn_energy_J=total([a.drawn_energy_J for a in parts]),
            energy_J=EnergyBreakdown(*(total([getattr(a.energy_J, k) for a in parts]) for k in ENERGY_PARTS)),
        )
    worst = min(range(len(summaries)), key=lambda k: summaries[k].worst_constraint.scaled_margin)
    colloc = [s.collocation_cost_W2s for s in summaries]
    colloc_viol = [s.collocation_max_violation for s in summaries]
    return DesignSummary(
        lengths=summaries[0].lengths,
        id_path=summaries[0].id_path,
        grid_points=sum(s.grid_points for s in summaries),
        cost_W2s=total([s.cost_W2s for s in summaries]),
        cost_note="sum over the tasks of weight x (1/2 Dt sum_k (sum_i P_i)^2) on each task's grid",
        net_electrical_energy_J=total([s.net_electrical_energy_J for s in summaries]),
        drawn_energy_summed_drives_J=total([s.drawn_energy_summed_drives_J for s in summaries]),
        drawn_energy_per_drive_sum_J=total([s.drawn_energy_per_drive_sum_J for s in summaries]),
        energy_breakdown_J=EnergyBreakdown(
            *(total([getattr(s.energy_breakdown_J, k) for s in summaries]) for k in ENERGY_PARTS)
        ),
        actuators=actuators,
        max_violation=max(s.max_violation for s in summaries),
        worst_constraint=WorstConstraint(
            f"{names[worst]}: {summaries[worst].worst_constraint.name}", summaries[worst].worst_constraint.scaled_margin
        ),
        tracking_error=worst_tracking([s.tracking_error for s in summaries]),
        collocation_cost_W2s=None if None in colloc else total([float(c or 0.0) for c in colloc]),
        collocation_max_violation=None if None in colloc_viol else max(float(v or 0.0) for v in colloc_viol),
    )


def weighted_recheck(rechecks: list[Recheck], weights: Array, names: list[str], fine_factor: int) -> Recheck:
    """The study's re-check: violations and force differences the worst, energy weighted (``fine_factor``: grid's)."""
    if is_one_task([float(v) for v in weights]):
        return rechecks[0]
    worst = min(range(len(rechecks)), key=lambda k: rechecks[k].worst_constraint.scaled_margin)
    return Recheck(
        id_path=rechecks[0].id_path,
        grid_points=sum(r.grid_points for r in rechecks),
        note=f"every task's optimal design re-evaluated on its {fine_factor}x finer grid with the other ID path "
        "and nominal bands",
        max_violation_scaled=max(r.max_violation_scaled for r in rechecks),
        worst_constraint=WorstConstraint(
            f"{names[worst]}: {rechecks[worst].worst_constraint.name}", rechecks[worst].worst_constraint.scaled_margin
        ),
        tracking_error=worst_tracking([r.tracking_error for r in rechecks]),
        net_electrical_energy_J=float(
            sum(w * r.net_electrical_energy_J for w, r in zip(weights, rechecks, strict=True))
        ),
        initial_max_violation_scaled=max(r.initial_max_violation_scaled for r in rechecks),
        force_difference_between_paths_N=max(r.force_difference_between_paths_N for r in rechecks),
    )


def weighted_decomposition(parts: list[Decomposition], weights: Array) -> Decomposition:
    """The tasks' saving decompositions weighted (a combination is evaluable when it is on every task)."""
    w = [float(v) for v in weights]
    if is_one_task(w):
        return parts[0]
    designs = {}
    for key, first in parts[0].designs.items():
        each = [p.designs[key] for p in parts]
        if all(d.evaluable for d in each):
            designs[key] = DecompositionDesign(
                first.lengths,
                first.trajectory,
                evaluable=True,
                net_electrical_energy_J=sum(
                    wk * float(d.net_electrical_energy_J or 0.0) for wk, d in zip(w, each, strict=True)
                ),
                drawn_energy_summed_drives_J=sum(
                    wk * float(d.drawn_energy_summed_drives_J or 0.0) for wk, d in zip(w, each, strict=True)
                ),
                cost_W2s=sum(wk * float(d.cost_W2s or 0.0) for wk, d in zip(w, each, strict=True)),
                collocation_cost_W2s=sum(
                    wk * float(d.collocation_cost_W2s or 0.0) for wk, d in zip(w, each, strict=True)
                ),
                max_violation=max(float(d.max_violation or 0.0) for d in each),
            )
        else:
            errors = "; ".join(str(d.error) for d in each if not d.evaluable)
            designs[key] = DecompositionDesign(first.lengths, first.trajectory, evaluable=False, error=errors)

    def total(key: str) -> float | None:
        values = [getattr(p, key) for p in parts]
        return None if None in values else float(sum(wk * v for wk, v in zip(w, values, strict=True)))

    base = designs["initial_lengths_initial_trajectory"].net_electrical_energy_J
    lengths, trajectory = total("from_lengths_J"), total("from_trajectory_J")
    return Decomposition(
        note="the tasks' decompositions (design_check.energy_decomposition) weighted by the tasks' weights",
        designs=designs,
        from_lengths_J=lengths,
        from_lengths_percent=None if lengths is None or not base else 100.0 * lengths / base,
        from_trajectory_J=trajectory,
        from_trajectory_percent=None if trajectory is None or not base else 100.0 * trajectory / base,
        interaction_J=total("interaction_J"),
        total_J=total("total_J"),
    )

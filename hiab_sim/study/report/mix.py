"""Result of a duty-mix optimisation: per-task sections, the mix's weighted summaries, the cross-evaluation.

Each task is reported as a single-task study would be (:func:`hiab_sim.study.report.result_folder.design_summary`
on its fine grid with nominal bands, re-checked with the other ID path): initial and optimal
energies (net and drawn), peaks, tracking error, and its ``energy`` section (battery energy,
costf2, thermal state over its own cycle at the study's duty). The top-level
``initial``/``optimal``/``recheck``/``energy`` of ``result.json`` hold the mix: energies and costs
weighted by the tasks' weights (per unit of the weights, e.g. per hour for cycles per hour), peaks
and violations the worst over the tasks, worst constraints named ``<task>: <row>``.
``trajectory.npz`` holds the first task under the renderer's keys (``time``, ``reference_tcp``,
``initial_*``, ``optimal_*``) and every task k under ``task<k>_<key>``.
"""

from __future__ import annotations

from dataclasses import replace

from hiab_sim.results.schema import (
    ENERGY_PARTS,
    ActuatorSummary,
    CrossEvaluation,
    Decomposition,
    DecompositionDesign,
    DesignSummary,
    EnergyBreakdown,
    HistoryRow,
    Improvement,
    Recheck,
    Result,
    Settings,
    TaskResult,
    TrackingError,
    WorstConstraint,
)
from hiab_sim.study.nlp.interface import Array
from hiab_sim.study.nlp.mix import MixProblem
from hiab_sim.study.report.energy_section import energy_report, study_duty, weighted_energy_report
from hiab_sim.study.report.result_folder import (
    DesignCheck,
    design_summary,
    energy_decomposition,
    fine_problem,
    multistart_summary,
    other_path,
    recheck_section,
    tracking_bands,
    trajectory_arrays,
)
from hiab_sim.study.report.solver_section import solver_summary
from hiab_sim.study.solvers.slsqp import SolveResult

TELESCOPE = "prescribed by the reference (third tracked coordinate xt2)"


def weighted_summary(summaries: list[DesignSummary], weights: Array, names: list[str]) -> DesignSummary:
    """The mix's summary: energies and costs weighted, peaks and violations the worst over the tasks."""
    w = [float(v) for v in weights]

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
        tracking_error=TrackingError(
            *(max(getattr(s.tracking_error, k) for s in summaries) for k in vars(summaries[0].tracking_error))
        ),
        collocation_cost_W2s=None if None in colloc else total([float(c or 0.0) for c in colloc]),
        collocation_max_violation=None if None in colloc_viol else max(float(v or 0.0) for v in colloc_viol),
    )


def weighted_recheck(rechecks: list[Recheck], weights: Array, names: list[str]) -> Recheck:
    """The mix's re-check: violations and force differences the worst, energy weighted."""
    worst = min(range(len(rechecks)), key=lambda k: rechecks[k].worst_constraint.scaled_margin)
    return Recheck(
        id_path=rechecks[0].id_path,
        grid_points=sum(r.grid_points for r in rechecks),
        note="every task's optimal design re-evaluated on its 10x finer grid with the other ID path and nominal bands",
        max_violation_scaled=max(r.max_violation_scaled for r in rechecks),
        worst_constraint=WorstConstraint(
            f"{names[worst]}: {rechecks[worst].worst_constraint.name}", rechecks[worst].worst_constraint.scaled_margin
        ),
        tracking_error=TrackingError(
            *(max(getattr(r.tracking_error, k) for r in rechecks) for k in vars(rechecks[0].tracking_error))
        ),
        net_electrical_energy_J=float(
            sum(w * r.net_electrical_energy_J for w, r in zip(weights, rechecks, strict=True))
        ),
        initial_max_violation_scaled=max(r.initial_max_violation_scaled for r in rechecks),
        force_difference_between_paths_N=max(r.force_difference_between_paths_N for r in rechecks),
    )


def weighted_decomposition(parts: list[Decomposition], weights: Array) -> Decomposition:
    """The tasks' saving decompositions weighted (a combination is evaluable when it is on every task)."""
    w = [float(v) for v in weights]
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
        note="the tasks' decompositions (report.energy_decomposition) weighted by the tasks' weights",
        designs=designs,
        from_lengths_J=lengths,
        from_lengths_percent=None if lengths is None or not base else 100.0 * lengths / base,
        from_trajectory_J=trajectory,
        from_trajectory_percent=None if trajectory is None or not base else 100.0 * trajectory / base,
        interaction_J=total("interaction_J"),
        total_J=total("total_J"),
    )


def build_mix_result(
    problem: MixProblem,
    results: list[SolveResult],
    wall_time: float,
    cross: CrossEvaluation | None = None,
    multistart_tolerance: float = 1e-4,
) -> tuple[Result, dict[str, Array], dict[str, DesignCheck]]:
    """Assemble result.json, trajectory.npz arrays and the first task's fine-grid checks (module docstring)."""
    main = results[0]
    names = [task.name for task in problem.tasks]
    task_results: list[TaskResult] = []
    arrays: dict[str, Array] = {}
    first_checks: dict[str, DesignCheck] = {}
    decompositions = []
    fines = []
    for k, (task, p) in enumerate(zip(problem.tasks, problem.problems, strict=True)):
        fine, recheck = fine_problem(p), fine_problem(p, other_path(p.id_path))
        fines.append(fine)
        z0, z1 = problem.task_z(main.z0, k), problem.task_z(main.z, k)
        checks = {
            "initial": design_summary(fine, z0),
            "optimal": design_summary(fine, z1),
            "recheck_initial": design_summary(recheck, z0),
            "recheck_optimal": design_summary(recheck, z1),
        }
        designs = {
            name: replace(
                checks[name].summary,
                collocation_cost_W2s=p.evaluate(z).cost,
                collocation_max_violation=p.max_violation(z),
            )
            for name, z in (("initial", z0), ("optimal", z1))
        }
        task_results.append(
            TaskResult(
                name=task.name,
                weight=task.weight,
                kind=task.reference.kind,
                duration_s=task.reference.duration,
                payload_kg=task.payload.mass,
                telescope=TELESCOPE,
                spline_control_points=p.basis.n,
                collocation_points=len(p.times),
                initial=designs["initial"],
                optimal=designs["optimal"],
                recheck=recheck_section(checks, recheck),
                energy=energy_report(fine, checks["initial"].evaluation, checks["optimal"].evaluation),
            )
        )
        decompositions.append(energy_decomposition(p, fine, z0, z1))
        if k == 0:
            first_checks = checks
        arrays.update(trajectory_arrays(fine, checks, f"task{k}_"))
        if k == 0:
            arrays.update(trajectory_arrays(fine, checks))
    w = problem.weights
    initial = weighted_summary([t.initial for t in task_results], w, names)
    optimal = weighted_summary([t.optimal for t in task_results], w, names)
    e0, e1 = initial.net_electrical_energy_J, optimal.net_electrical_energy_J
    cost0, cost1 = problem.evaluate(main.z0).cost, problem.evaluate(main.z).cost
    solver = solver_summary(problem, main, wall_time)

    def mix_energy(z: Array) -> float:
        return float(
            sum(
                wk * design_summary(f, problem.task_z(z, k)).summary.net_electrical_energy_J
                for k, (wk, f) in enumerate(zip(w, fines, strict=True))
            )
        )

    study = problem.study
    result = Result(
        crane=study.crane_source,
        study=study.path,
        name=study.name,
        initial=initial,
        optimal=optimal,
        improvement=Improvement(
            cost_ratio=cost1 / cost0,
            net_energy_saved_J=e0 - e1,
            net_energy_saved_percent=100.0 * (e0 - e1) / e0,
            decomposition=weighted_decomposition(decompositions, w),
        ),
        solver=solver,
        recheck=weighted_recheck([t.recheck for t in task_results], w, names),
        multistart=multistart_summary(problem, results, multistart_tolerance, energy=mix_energy),
        settings=Settings(
            spline_control_points=sum(p.basis.n for p in problem.problems),
            spline_degree=problem.problems[0].basis.k,
            collocation_points=sum(len(p.times) for p in problem.problems),
            collocation_step_s=problem.problems[0].dt,
            fine_grid_points=sum(len(f.times) for f in fines),
            redundancy=f"xt2 {TELESCOPE} in every task; counts summed over the tasks",
            tracking_bands=tracking_bands(study),
            xi_low=tuple(study.bounds.xi_low),
            xi_up=tuple(study.bounds.xi_up),
            envelope_margin=study.bounds.envelope_margin,
            payload_kg=study.payload,
        ),
        history=tuple(
            HistoryRow(h.iteration, h.cost, h.scaled_cost, h.max_violation, tuple(h.xi), h.wall_time)
            for h in main.history
        ),
        tasks=tuple(task_results),
        cross_evaluation=cross,
        energy=weighted_energy_report(
            [t.energy for t in task_results if t.energy is not None],
            w.tolist(),
            [task.reference.duration for task in problem.tasks],
            [study_duty(f)[0].period for f in fines],
        ),
    )
    return result, arrays, first_checks

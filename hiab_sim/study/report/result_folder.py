"""Result folder of an optimisation: ``result.json`` and ``trajectory.npz`` of a study of one task or many.

Contract with the renderer: ``result.json`` has top-level ``crane`` (preset name or
path as given in the study), ``study`` (path), ``initial`` and ``optimal``, each with
``lengths`` = {"lift": {"L", "Lc0", "Lc"}, "tilt": {...}}; ``trajectory.npz`` has ``time`` (K,)
on the fine grid, ``reference_tcp`` (K, 3) in {W} and ``{initial,optimal}_{position,velocity,
acceleration}`` (K, 3) = (theta1, theta2, xt2) of the first task, and with several tasks every
task k under ``task<k>_<key>``. Every file is written atomically.

One builder for any number of tasks: each task is evaluated by :mod:`hiab_sim.study.report.design_check`
(fine grid, re-check on the other ID path, energy section), and the study's sections combine them
(:mod:`hiab_sim.study.report.weighted`: a single task of weight 1 is reported as itself). With several
tasks ``tasks`` holds each task's sections (its own ``structure`` among them), ``structure`` their
envelope (:func:`hiab_sim.structure.summary.mix_structure`) and ``cross_evaluation`` the designs x
tasks table.
Every ``cost_W2s`` is eq. ``costf2`` [W^2 s] whatever the objective; the objective's own value is
in ``energy`` (battery energy [J]), ``sensitivity.objective_value`` and the history.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.atomic_io import write_atomic
from hiab_sim.percent import saving_percent
from hiab_sim.results.multistart import DistinctOptimum, FailedStart, MultiStart, StartRow
from hiab_sim.results.schema import (
    RESULT_FILE,
    CrossEvaluation,
    HistoryRow,
    Improvement,
    Result,
    Settings,
    TaskResult,
)
from hiab_sim.results.trajectory_file import write_trajectory
from hiab_sim.structure.summary import mix_structure
from hiab_sim.study.nlp.objectives import costf2, exact_value
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.report.design_check import (
    DesignCheck,
    design_summary,
    energy_decomposition,
    recheck_section,
    task_checks,
    tracking_bands,
    trajectory_arrays,
)
from hiab_sim.study.report.energy_section import (
    energy_report,
    hydraulic_report,
    study_duty,
    weighted_energy_report,
)
from hiab_sim.study.report.solver_section import solver_summary
from hiab_sim.study.report.structure_section import structure_section
from hiab_sim.study.report.weighted import (
    TELESCOPE,
    is_one_task,
    weighted_decomposition,
    weighted_recheck,
    weighted_summary,
)
from hiab_sim.study.solvers.slsqp import SolveResult


def collocation_costf2(problem: StudyProblem, z: Array) -> float:
    """sum_k w_k costf2_k [W^2 s] on the tasks' collocation grids, whatever the study's objective."""
    ev = problem.evaluate(z)
    return float(
        sum(
            w * costf2(p.emlas, p.dt).value(e)
            for w, p, e in zip(problem.weights, problem.problems, ev.tasks, strict=True)
        )
    )


def build_result(
    problem: StudyProblem,
    results: list[SolveResult],
    wall_time: float,
    cross: CrossEvaluation | None = None,
    multistart_tolerance: float = 1e-4,
) -> tuple[Result, dict[str, Array], dict[str, DesignCheck]]:
    """Assemble result.json, trajectory.npz arrays and the first task's fine-grid checks (module docstring)."""
    main = results[0]
    names = [task.name for task in problem.tasks]
    w = problem.weights
    one = is_one_task([float(v) for v in w])
    task_results: list[TaskResult] = []
    arrays: dict[str, Array] = {}
    first_checks: dict[str, DesignCheck] = {}
    decompositions, fines, energies, structures = [], [], [], []
    for k, (task, p) in enumerate(zip(problem.tasks, problem.problems, strict=True)):
        z0, z1 = problem.task_z(main.z0, k), problem.task_z(main.z, k)
        checks, fine, recheck = task_checks(p, z0, z1)
        fines.append(fine)
        designs = {
            name: replace(
                checks[name].summary,
                collocation_cost_W2s=costf2(p.emlas, p.dt).value(p.evaluate(z)),
                collocation_max_violation=p.max_violation(z),
            )
            for name, z in (("initial", z0), ("optimal", z1))
        }
        energies.append(energy_report(fine, checks["initial"].evaluation, checks["optimal"].evaluation))
        structures.append(structure_section(fine, checks))  # the task's own motion and payload
        task_results.append(
            TaskResult(
                name=task.name,
                weight=task.weight,
                kind=task.reference.kind,
                duration_s=task.reference.duration,
                payload_kg=task.payload.mass,
                telescope=TELESCOPE if problem.study.crane_description is not None else None,  # a machine: none
                spline_control_points=p.basis.n,
                collocation_points=len(p.times),
                initial=designs["initial"],
                optimal=designs["optimal"],
                recheck=recheck_section(checks, recheck),
                energy=energies[-1],
                structure=structures[-1],
            )
        )
        decompositions.append(energy_decomposition(p, fine, z0, z1))
        task_arrays = trajectory_arrays(fine, checks)  # once per task: the battery trace solves the duty again
        if k == 0:
            first_checks = checks
            arrays.update(task_arrays)
        if not one:  # a mix, or one task of another weight: the top level is a weighted sum, each task its own
            arrays.update({f"task{k}_{key}": value for key, value in task_arrays.items()})
    initial = weighted_summary([t.initial for t in task_results], w, names)
    optimal = weighted_summary([t.optimal for t in task_results], w, names)
    e0, e1 = initial.net_electrical_energy_J, optimal.net_electrical_energy_J
    cost0, cost1 = problem.evaluate(main.z0).cost, problem.evaluate(main.z).cost

    def study_energy(z: Array) -> float:
        return float(
            sum(
                wk * design_summary(f, problem.task_z(z, k)).summary.net_electrical_energy_J
                for k, (wk, f) in enumerate(zip(w, fines, strict=True))
            )
        )

    def study_objective(z: Array) -> float:
        return float(
            sum(
                wk * exact_value(f.objective, f.evaluate(problem.task_z(z, k)))
                for k, (wk, f) in enumerate(zip(w, fines, strict=True))
            )
        )

    study = problem.study
    first = problem.problems[0]
    energy = (
        energies[0]
        if one
        else weighted_energy_report(
            energies,
            w.tolist(),
            [task.reference.duration for task in problem.tasks],
            [study_duty(f)[0].period for f in fines],
        )
    )
    result = Result(
        crane=study.crane_source,
        study=study.path,
        name=study.name,
        initial=initial,
        optimal=optimal,
        improvement=Improvement(
            cost_ratio=cost1 / cost0,
            net_energy_saved_J=e0 - e1,
            net_energy_saved_percent=saving_percent(e0, e1),
            decomposition=weighted_decomposition(decompositions, w),
        ),
        solver=solver_summary(problem, main, wall_time),
        recheck=weighted_recheck([t.recheck for t in task_results], w, names, study.grid.fine_factor),
        multistart=multistart_summary(
            problem, results, multistart_tolerance, energy=study_energy, objective=study_objective
        ),
        settings=Settings(
            spline_control_points=sum(p.basis.n for p in problem.problems),
            spline_degree=first.basis.k,
            collocation_points=sum(len(p.times) for p in problem.problems),
            collocation_step_s=first.dt,
            fine_grid_points=sum(len(f.times) for f in fines),
            redundancy=(
                (
                    "xt2 prescribed by the study (third reference coordinate)"
                    if problem.n_tasks == 1
                    else f"xt2 {TELESCOPE} in every task; counts summed over the tasks"
                )
                if study.crane_description is not None
                else f"tracked: {', '.join(problem.model.tracked_names)} (one per joint: the IK is square)"
            ),
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
        energy=energy,
        hydraulic_baseline=(
            hydraulic_report(fines[0], first_checks["initial"].evaluation, first_checks["optimal"].evaluation, energy)
            if one
            else None
        ),
        tasks=None if one else tuple(task_results),
        cross_evaluation=cross,
        # one task: its own section; a mix: the envelope over its tasks (each task's own under tasks)
        structure=structures[0] if problem.n_tasks == 1 else mix_structure(structures, names),
    )
    return result, arrays, first_checks


def write_results(out: Path, result: Result, arrays: dict[str, Array]) -> None:
    """Write ``result.json`` and ``trajectory.npz`` (its declared schema) atomically."""
    write_trajectory(out, arrays)
    write_atomic(out / RESULT_FILE, json.dumps(result.to_json(), indent=2) + "\n")


def multistart_summary(
    problem: StudyProblem,
    results: list[SolveResult],
    tolerance: float,
    energy: Callable[[Array], float] | None = None,
    objective: Callable[[Array], float] | None = None,
) -> MultiStart:
    """Whether every converged start reached the same Xi within ``tolerance`` [m]; else the distinct optima.

    A start whose solver failed is no optimum: it is left out of ``distinct_optima`` and listed
    under ``failed_starts`` with its message (its row has no optimal lengths or cost). ``energy``
    gives a design's net energy [J] (the weighted sum over the tasks' fine grids; None: not given),
    ``objective`` the study's objective there [its unit], exact where it smooths for the solver.
    """
    rows: list[StartRow] = []
    failed: list[FailedStart] = []
    for r in results:
        optimal, cost = None, None
        if r.success:
            ev = problem.evaluate(r.z)
            optimal = ev.lengths
            cost = collocation_costf2(problem, r.z)  # costf2 whatever the objective
        else:
            failed.append(FailedStart(r.start, tuple(r.initial_lengths.as_array().tolist()), r.message))
        rows.append(StartRow(r.start, r.initial_lengths, optimal, cost, r.success, r.message, r.iterations))
    groups: list[tuple[Array, float | None, list[int]]] = []  # (Xi, cost of its first start, starts)
    for r, row in zip(results, rows, strict=True):
        if not r.success:
            continue
        xi = problem.unpack(r.z)[0].as_array()
        for group in groups:
            if np.max(np.abs(group[0] - xi)) <= tolerance:
                group[2].append(r.start)
                break
        else:
            groups.append((xi, row.cost_W2s, [r.start]))
    by_start = {r.start: r for r in results}
    distinct = tuple(
        DistinctOptimum(
            xi=tuple(xi.tolist()),
            cost_W2s=cost,
            starts=tuple(starts),
            net_electrical_energy_J=None if energy is None or len(results) < 2 else energy(by_start[starts[0]].z),
            objective_value=None if objective is None or len(results) < 2 else objective(by_start[starts[0]].z),
        )
        for xi, cost, starts in groups
    )
    return MultiStart(
        starts=tuple(rows),
        tolerance_m=tolerance,
        converged_starts=len(results) - len(failed),
        same_optimum=len(distinct) == 1,
        distinct_optima=distinct,
        failed_starts=tuple(failed),
        objective=None if objective is None else problem.study.energy.objective,
        objective_unit=None if objective is None else problem.objective.unit,
    )

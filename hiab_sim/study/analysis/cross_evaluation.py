"""The price of robustness: every task's optimum alone and the mix optimum, each evaluated on every task.

A design is a set of link lengths Xi. Evaluating it on a task re-optimises that task's trajectory
at fixed Xi (:func:`fixed_lengths_optimum`: the task's NLP over its spline coefficients only, i.e.
the Xi bounds collapsed to the design), because a crane built with those lengths would be driven
as well as it can on that task: from the inverse-kinematics fit, and for the mix optimum also from
its own optimal trajectory, keeping the better (:func:`best_fixed_lengths_optimum`). Evaluating
it on the mix is the weighted sum over the tasks (the mix's NLP decouples into the tasks once Xi
is fixed). The matrix rows are the designs, the columns the tasks: net electrical energy and
energy drawn on each task's fine grid (nominal bands), the cost of eq. ``costf2`` [W^2 s] and the
study's objective [its unit] on its collocation grid, and the largest violation.
``mix_energy_lost`` is what a single-task design costs the mix in net energy over the mix
optimum. The optimum minimises the study's objective, so an energy "loss" may be negative; so may
the cost loss, by the spread of the non-convex NLP's local optima (~1e-5 relative on the test
studies): each optimum is local, from its own start.
"""

from __future__ import annotations

import copy
from dataclasses import replace

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError, SolverError
from hiab_sim.percent import change_percent
from hiab_sim.results.analysis_sections import CrossEvaluation
from hiab_sim.results.design_values import DesignValues
from hiab_sim.study.nlp.objectives import costf2
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.report.design_check import design_summary, fine_problem
from hiab_sim.study.solvers.ipopt import solve_ipopt
from hiab_sim.study.solvers.slsqp import solve
from hiab_sim.study.spec.study_file import Study

#: Largest scaled violation of a design's re-optimised trajectory that counts as serving the task.
FEASIBLE = 1e-6


def task_alone(study: Study, k: int) -> StudyProblem:
    """Task k of a study as a study of its own (weight 1: its NLP is the task's, bit for bit)."""
    task = replace(study.tasks[k], weight=1.0)
    return StudyProblem(replace(study, tasks=(task,)))


def fixed_lengths_optimum(
    problem: StudyProblem, lengths: DesignValues, coefficients: Array | None = None
) -> tuple[Array, bool, str]:
    """The task's best trajectory for fixed link lengths: IPOPT on the task's NLP with Xi fixed.

    The Xi bounds are collapsed to the design (IPOPT treats Xi as fixed parameters). IPOPT, not
    SLSQP: started from the inverse-kinematics fit at a fixed Xi, SLSQP over the coefficients
    stops with "positive directional derivative for linesearch" at violations of ~1e-3 (measured
    on the two-task test study, even for a task's own optimal Xi), where IPOPT converges to < 1e-8.

    Args:
        problem: The task's NLP (:func:`task_alone`: collocation grid, tightened bands).
        lengths: The design Xi [m].
        coefficients: Start coefficients (3, N) (default: the inverse-kinematics fit).

    Returns:
        (z of the task's NLP, success, solver message); the point is used when it is feasible
        (:data:`FEASIBLE`).

    """
    z0 = problem.initial_point(lengths, None if coefficients is None else [coefficients])
    settings = problem.study.solver
    fixed = copy.copy(problem)  # the same NLP (and caches) with the Xi bounds collapsed to the design
    fixed.lower, fixed.upper = problem.lower.copy(), problem.upper.copy()
    n_xi = problem.n_xi  # the study's design variables (6 on the XS 031, the machine file's count otherwise)
    fixed.lower[:n_xi] = fixed.upper[:n_xi] = z0[:n_xi]
    outcome = solve_ipopt(fixed, z0, settings.maxiter, settings.ftol, history=settings.lbfgs_history)
    return outcome.z, outcome.success, outcome.message


def best_fixed_lengths_optimum(
    problem: StudyProblem, rows: TaskProblem, lengths: DesignValues, starts: list[Array | None]
) -> tuple[Array, str]:
    """The best of :func:`fixed_lengths_optimum` from each start: the least objective among the feasible ends.

    The fixed-Xi NLP is not convex: on the two-task test study the mix optimum's own trajectory of its
    second task is a local optimum 1.8 % above the one IPOPT reaches from the inverse-kinematics fit
    at the same Xi. ``rows`` is the task's NLP whose violation decides feasibility (:data:`FEASIBLE`);
    with no feasible end, the first finished start's end (and its message) is returned. A start whose
    solve raises (a design outside the model's domain, a failed solve) leaves the others to answer;
    when every start raises, the first error is raised.
    """
    ends: list[tuple[Array, str]] = []
    errors: list[InvalidInputError | SolverError] = []
    for start in starts:
        try:
            z, _, message = fixed_lengths_optimum(problem, lengths, start)
        except (InvalidInputError, SolverError) as error:
            errors.append(error)
        else:
            ends.append((z, message))
    if not ends:
        raise errors[0]
    feasible = [end for end in ends if rows.max_violation(end[0]) <= FEASIBLE]
    if not feasible:
        return ends[0]
    return min(feasible, key=lambda end: rows.evaluate(end[0]).cost)


def single_task_optima(alone: list[StudyProblem]) -> list[DesignValues]:
    """Each task's optimum alone, from the study's start (its own NLP, the study's solver settings)."""
    out = []
    for p in alone:
        result = solve(p, p.study.initial_lengths, progress=None)
        out.append(p.unpack(result.z)[0])
    return out


def cross_evaluation(mix: StudyProblem, z_mix: Array, alone: list[DesignValues] | None = None) -> CrossEvaluation:
    """Rows: each task's optimum alone, then the mix optimum ``z_mix``; columns: the tasks (module docstring)."""
    tasks = [task_alone(mix.study, k) for k in range(mix.n_tasks)]
    alone = single_task_optima(tasks) if alone is None else alone
    mix_lengths, mix_c = mix.unpack(z_mix)
    designs = [f"{task.name} alone" for task in mix.tasks] + ["mix"]
    lengths = [*alone, mix_lengths]
    fines = [fine_problem(p) for p in mix.problems]
    rows: dict[str, list[list[float | None]]] = {k: [] for k in ("net", "drawn", "cost", "viol", "objective")}
    why: list[tuple[str, ...]] = []
    for d, xi in enumerate(lengths):
        row: dict[str, list[float | None]] = {k: [] for k in rows}
        row_why: list[str] = []
        for k, (p, fine) in enumerate(zip(mix.problems, fines, strict=True)):
            starts: list[Array | None] = [None, mix_c[k]] if d == len(alone) else [None]
            values: tuple[float | None, ...] = (None, None, None, None, None)
            reason = ""
            # A design outside the model's domain or a failed solve is this cell's answer, said in
            # words; a missing backend (BackendUnavailableError) is not a cell's answer and propagates.
            try:
                z, message = best_fixed_lengths_optimum(tasks[k], p, xi, starts)
            except (InvalidInputError, SolverError) as error:
                reason = f"cannot be evaluated: {error}"
            else:
                violation = p.max_violation(z)
                if violation <= FEASIBLE:
                    summary = design_summary(fine, z).summary
                    values = (
                        summary.net_electrical_energy_J,
                        summary.drawn_energy_summed_drives_J,
                        costf2(p.emlas, p.dt).value(p.evaluate(z)),
                        summary.max_violation,
                        p.evaluate(z).cost,
                    )
                else:
                    reason = (
                        f"no feasible trajectory found: largest scaled violation {violation:.3g} > {FEASIBLE:g} "
                        f"(solver: {message})"
                    )
            for key, value in zip(row, values, strict=True):
                row[key].append(value)
            row_why.append(reason)
        for key in rows:
            rows[key].append(row[key])
        why.append(tuple(row_why))
    w = mix.weights

    def weighted(values: list[float | None]) -> float | None:
        if any(v is None for v in values):
            return None
        return float(sum(wk * float(v) for wk, v in zip(w, values, strict=True) if v is not None))

    mix_net = [weighted(r) for r in rows["net"]]
    mix_cost = [weighted(r) for r in rows["cost"]]
    best_net, best_cost = mix_net[-1], mix_cost[-1]

    def lost(values: list[float | None], best: float | None, percent: bool) -> list[float | None]:
        if best is None:
            return [None] * len(values)
        return [None if v is None else (change_percent(best, v) if percent else v - best) for v in values]

    return CrossEvaluation(
        note=(
            "rows: designs (each task's optimum alone, then the mix optimum); columns: tasks; trajectory "
            "re-optimised at fixed Xi; energies on each task's fine grid, costs on its collocation grid; "
            "mix = weighted sum over the tasks; None: the design cannot serve the task (why: unserved)"
        ),
        tasks=tuple(task.name for task in mix.tasks),
        weights=tuple(float(v) for v in w),
        designs=tuple(designs),
        lengths=tuple(lengths),
        net_energy_J=tuple(tuple(r) for r in rows["net"]),
        drawn_energy_J=tuple(tuple(r) for r in rows["drawn"]),
        cost_W2s=tuple(tuple(r) for r in rows["cost"]),
        max_violation=tuple(tuple(r) for r in rows["viol"]),
        mix_net_energy_J=tuple(mix_net),
        mix_cost_W2s=tuple(mix_cost),
        objective=mix.objective.name,
        objective_unit=mix.objective.unit,
        objective_value=tuple(tuple(r) for r in rows["objective"]),
        mix_objective_value=tuple(weighted(r) for r in rows["objective"]),
        mix_energy_lost_J=tuple(lost(mix_net, best_net, False)),
        mix_energy_lost_percent=tuple(lost(mix_net, best_net, True)),
        mix_cost_lost_percent=tuple(lost(mix_cost, best_cost, True)),
        unserved=tuple(why),
    )

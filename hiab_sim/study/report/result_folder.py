"""Result folder of an optimisation: ``result.json``, ``trajectory.npz`` and the design summaries.

Contract with the renderer: ``result.json`` has top-level ``crane`` (preset name or
path as given in the study), ``study`` (path), ``initial`` and ``optimal``, each with
``lengths`` = {"lift": {"L", "Lc0", "Lc"}, "tilt": {...}}; ``trajectory.npz`` has ``time`` (K,)
on the fine grid, ``reference_tcp`` (K, 3) in {W} and ``{initial,optimal}_{position,velocity,
acceleration}`` (K, 3) = (theta1, theta2, xt2). Every file is written atomically.

Energies are integrated on the fine grid (10x the collocation grid): the cost of eq. ``costf2``
is 1/2 Dt sum (sum_i P_i)^2 [W^2 s], a squared-power integral, not an energy, so the net
electrical energy (regeneration credited) and the energy drawn without regeneration are
reported separately, with the loss breakdown of :func:`hiab_sim.emla.operating_point`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiab_sim.atomic_io import write_atomic
from hiab_sim.emla import energy_summary, operating_point
from hiab_sim.errors import HiabSimError
from hiab_sim.quadrature import trapezoid
from hiab_sim.results.schema import (
    ENERGY_PARTS,
    RESULT_FILE,
    ActuatorSummary,
    Decomposition,
    DecompositionDesign,
    DesignSummary,
    DistinctOptimum,
    EnergyBreakdown,
    FailedStart,
    HistoryRow,
    Improvement,
    MultiStart,
    Recheck,
    Result,
    Settings,
    StartRow,
    TrackingBands,
    TrackingError,
    WorstConstraint,
)
from hiab_sim.results.trajectory_file import write_trajectory
from hiab_sim.study.nlp.mix import Problem
from hiab_sim.study.nlp.objectives import SquaredPowerCost
from hiab_sim.study.nlp.problem import ACTUATORS, Evaluation, LinkLengthProblem
from hiab_sim.study.report.energy_section import energy_report, hydraulic_report
from hiab_sim.study.report.solver_section import solver_summary
from hiab_sim.study.solvers.slsqp import SolveResult
from hiab_sim.study.spec.study_file import Study

Array = NDArray[np.float64]


@dataclass(frozen=True)
class DesignCheck:
    """A design evaluated on the fine grid by one ID path, with its summary."""

    evaluation: Evaluation
    summary: DesignSummary


def design_summary(problem: LinkLengthProblem, z: Array) -> DesignCheck:
    """Evaluate z on ``problem``'s grid (the fine grid, nominal bands): energies, peaks, violations."""
    ev = problem.evaluate(z)
    t = problem.times
    act = ev.actuators
    net, drawn = energy_summary(t, ev.power.T)
    breakdown = np.zeros(len(ENERGY_PARTS))
    per_actuator: dict[str, ActuatorSummary] = {}
    for i, (name, params) in enumerate(zip(ACTUATORS, problem.emlas, strict=True)):
        op = operating_point(params, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
        parts = EnergyBreakdown(
            mechanical=float(trapezoid(op.mechanical_power, t)),
            copper=float(trapezoid(op.copper_loss, t)),
            rotor_friction=float(trapezoid(op.rotor_friction_loss, t)),
            screw_viscous=float(trapezoid(op.screw_viscous_loss, t)),
            inertial=float(trapezoid(op.inertial_power, t)),
            electrical=float(trapezoid(op.electrical_power, t)),
        )
        breakdown += parts.as_tuple()
        per_actuator[name] = ActuatorSummary(
            peak_force_N=float(np.max(np.abs(act.force[:, i]))),
            peak_velocity_m_per_s=float(np.max(np.abs(act.velocity[:, i]))),
            peak_electrical_power_W=float(np.max(ev.power[:, i])),
            min_envelope_margin=float(op.margins.min()),
            net_energy_J=float(net[i]),
            drawn_energy_J=float(drawn[i]),
            energy_J=parts,
        )
    total_power = ev.power.sum(axis=1)
    net_total, drawn_total = energy_summary(t, total_power)
    ref = problem.reference
    err = TrackingError(
        position_m=float(np.max(np.abs(ev.tcp.position[:, :2] - ref.position[:, :2]))),
        velocity_m_per_s=float(np.max(np.abs(ev.tcp.velocity[:, :2] - ref.velocity[:, :2]))),
        acceleration_m_per_s2=float(np.max(np.abs(ev.tcp.acceleration[:, :2] - ref.acceleration[:, :2]))),
        telescope_m=float(np.max(np.abs(ev.tcp.position[:, 2] - ref.position[:, 2]))),
    )
    summary = DesignSummary(
        lengths=ev.lengths,
        id_path=problem.id_path,
        grid_points=len(t),
        cost_W2s=SquaredPowerCost(problem.emlas, problem.dt).value(ev),
        cost_note="1/2 Dt sum_k (sum_i P_i(t_k))^2 on this grid: a squared-power integral, not an energy",
        net_electrical_energy_J=float(net_total),
        drawn_energy_summed_drives_J=float(drawn_total),
        drawn_energy_per_drive_sum_J=float(np.sum(drawn)),
        energy_breakdown_J=EnergyBreakdown(*(float(v) for v in breakdown)),
        actuators=per_actuator,
        max_violation=problem.max_violation(z),
        worst_constraint=worst_constraint(problem, z),
        tracking_error=err,
    )
    return DesignCheck(ev, summary)


def worst_constraint(problem: LinkLengthProblem, z: Array) -> WorstConstraint:
    """The constraint row of least scaled margin at z."""
    margins = problem.margins(z)
    worst = int(np.argmin(margins))
    return WorstConstraint(problem.constraint_names[worst], float(margins[worst]))


def fine_problem(problem: LinkLengthProblem, id_path: str | None = None) -> LinkLengthProblem:
    """The same study on the fine grid with nominal bands (for reports and the re-check)."""
    return LinkLengthProblem(
        problem.study,
        emlas=problem.emlas,
        id_path=id_path or problem.id_path,
        times=problem.fine_times(),
        cost_scale=problem.cost_scale,
        tightened=False,
        task=problem.task,
    )


def other_path(path: str) -> str:
    """The other inverse-dynamics path."""
    return "analytic" if path == "mujoco" else "mujoco"


def build_result(
    problem: LinkLengthProblem, results: list[SolveResult], wall_time: float, multistart_tolerance: float = 1e-4
) -> tuple[Result, dict[str, Array], dict[str, DesignCheck]]:
    """Assemble result.json, trajectory.npz arrays and the fine-grid checks (keys initial/optimal/recheck_*)."""
    main = results[0]
    fine = fine_problem(problem)
    recheck = fine_problem(problem, other_path(problem.id_path))
    checks = {
        "initial": design_summary(fine, main.z0),
        "optimal": design_summary(fine, main.z),
        "recheck_initial": design_summary(recheck, main.z0),
        "recheck_optimal": design_summary(recheck, main.z),
    }
    colloc = {name: problem.evaluate(z) for name, z in (("initial", main.z0), ("optimal", main.z))}
    designs = {
        name: replace(
            checks[name].summary,
            collocation_cost_W2s=SquaredPowerCost(problem.emlas, problem.dt).value(colloc[name]),
            collocation_max_violation=problem.max_violation(colloc[name].z),
        )
        for name in ("initial", "optimal")
    }
    e0 = designs["initial"].net_electrical_energy_J
    e1 = designs["optimal"].net_electrical_energy_J
    improvement = Improvement(
        cost_ratio=colloc["optimal"].cost / colloc["initial"].cost,
        net_energy_saved_J=e0 - e1,
        net_energy_saved_percent=100.0 * (e0 - e1) / e0,
        decomposition=energy_decomposition(problem, fine, main.z0, main.z),
    )
    solver = solver_summary(problem, main, wall_time)
    recheck_summary = recheck_section(checks, recheck)
    study = problem.study
    settings = Settings(
        spline_control_points=problem.basis.n,
        spline_degree=problem.basis.k,
        collocation_points=len(problem.times),
        collocation_step_s=problem.dt,
        fine_grid_points=len(fine.times),
        redundancy="xt2 prescribed by the study (third reference coordinate)",
        tracking_bands=tracking_bands(study),
        xi_low=tuple(study.bounds.xi_low),
        xi_up=tuple(study.bounds.xi_up),
        envelope_margin=study.bounds.envelope_margin,
        payload_kg=study.payload,
    )
    energy = energy_report(fine, checks["initial"].evaluation, checks["optimal"].evaluation)
    result = Result(
        crane=study.crane_source,
        study=study.path,
        name=study.name,
        initial=designs["initial"],
        optimal=designs["optimal"],
        improvement=improvement,
        solver=solver,
        recheck=recheck_summary,
        multistart=multistart_summary(problem, results, multistart_tolerance),
        settings=settings,
        history=tuple(
            HistoryRow(h.iteration, h.cost, h.scaled_cost, h.max_violation, tuple(h.xi), h.wall_time)
            for h in main.history
        ),
        energy=energy,
        hydraulic_baseline=hydraulic_report(fine, checks["initial"].evaluation, checks["optimal"].evaluation, energy),
    )
    return result, trajectory_arrays(fine, checks), checks


def trajectory_arrays(fine: LinkLengthProblem, checks: dict[str, DesignCheck], prefix: str = "") -> dict[str, Array]:
    """``trajectory.npz``'s arrays of one task on its fine grid (SI units; keys prefixed by ``prefix``)."""
    arrays: dict[str, Array] = {f"{prefix}time": fine.times, f"{prefix}reference_tcp": fine.reference.tcp()}
    for name in ("initial", "optimal"):
        ev = checks[name].evaluation
        arrays[f"{prefix}{name}_position"] = ev.joints.position
        arrays[f"{prefix}{name}_velocity"] = ev.joints.velocity
        arrays[f"{prefix}{name}_acceleration"] = ev.joints.acceleration
        arrays[f"{prefix}{name}_tcp"] = fine.kin.position(ev.joints.position)
        arrays[f"{prefix}{name}_actuator_force"] = ev.actuators.force
        arrays[f"{prefix}{name}_actuator_velocity"] = ev.actuators.velocity
        arrays[f"{prefix}{name}_actuator_stroke"] = ev.actuators.stroke
        arrays[f"{prefix}{name}_electrical_power"] = ev.power
    return arrays


def recheck_section(checks: dict[str, DesignCheck], recheck: LinkLengthProblem) -> Recheck:
    """The re-check section from the fine-grid checks (keys optimal, recheck_initial, recheck_optimal)."""
    rc = checks["recheck_optimal"].summary
    force_difference = np.abs(
        checks["optimal"].evaluation.actuators.force - checks["recheck_optimal"].evaluation.actuators.force
    )
    return Recheck(
        id_path=recheck.id_path,
        grid_points=len(recheck.times),
        note="optimal design re-evaluated on the 10x finer grid with the other ID path and nominal bands",
        max_violation_scaled=rc.max_violation,
        worst_constraint=rc.worst_constraint,
        tracking_error=rc.tracking_error,
        net_electrical_energy_J=rc.net_electrical_energy_J,
        initial_max_violation_scaled=checks["recheck_initial"].summary.max_violation,
        force_difference_between_paths_N=float(np.max(force_difference)),
    )


#: The four designs of :func:`energy_decomposition`: (key, lengths from, trajectory from).
DECOMPOSITION_DESIGNS = (
    ("initial_lengths_initial_trajectory", "initial", "initial"),
    ("optimal_lengths_initial_trajectory", "optimal", "initial"),
    ("initial_lengths_optimal_trajectory", "initial", "optimal"),
    ("optimal_lengths_optimal_trajectory", "optimal", "optimal"),
)


def energy_decomposition(
    problem: LinkLengthProblem, fine: LinkLengthProblem, z_initial: Array, z_optimal: Array
) -> Decomposition:
    """Split the saving into what the lengths and what the re-shaped trajectory contribute.

    The spline coefficients are decision variables free within the tracking bands, so the
    optimum changes the trajectory as well as the mounting. Each of the four combinations of
    {initial, optimal} lengths with the {initial, optimal} coefficients is evaluated on the fine
    grid (nominal bands): net energy, cost (fine and collocation grid) and max violation (a
    mixed design need not be feasible). ``from_lengths`` is the saving of the optimal lengths
    with the initial trajectory, ``from_trajectory`` that of the optimal trajectory with the
    initial lengths (both relative to the initial design), ``interaction`` the rest of the total.
    """
    n = problem.n_xi
    source = {"initial": np.asarray(z_initial, dtype=float), "optimal": np.asarray(z_optimal, dtype=float)}
    designs: dict[str, DecompositionDesign] = {}
    energy: dict[str, float] = {}
    for key, xi_from, c_from in DECOMPOSITION_DESIGNS:
        z = np.concatenate([source[xi_from][:n], source[c_from][n:]])
        try:
            summary = design_summary(fine, z).summary
            collocation_cost = SquaredPowerCost(problem.emlas, problem.dt).value(problem.evaluate(z))
        except HiabSimError as error:  # a mixed design may leave the model's domain
            designs[key] = DecompositionDesign(xi_from, c_from, evaluable=False, error=str(error))
            energy[key] = float("nan")
        else:
            energy[key] = summary.net_electrical_energy_J
            designs[key] = DecompositionDesign(
                xi_from,
                c_from,
                evaluable=True,
                net_electrical_energy_J=summary.net_electrical_energy_J,
                drawn_energy_summed_drives_J=summary.drawn_energy_summed_drives_J,
                cost_W2s=summary.cost_W2s,
                collocation_cost_W2s=collocation_cost,
                max_violation=summary.max_violation,
                worst_constraint=summary.worst_constraint,
            )
    e00 = energy["initial_lengths_initial_trajectory"]
    lengths = e00 - energy["optimal_lengths_initial_trajectory"]
    trajectory = e00 - energy["initial_lengths_optimal_trajectory"]
    total = e00 - energy["optimal_lengths_optimal_trajectory"]

    def finite(x: float) -> float | None:
        return float(x) if np.isfinite(x) else None

    return Decomposition(
        note=(
            "net electrical energy on the fine grid of the four combinations of initial/optimal lengths and "
            "initial/optimal spline coefficients; savings relative to the initial design"
        ),
        designs=designs,
        from_lengths_J=finite(lengths),
        from_lengths_percent=finite(100.0 * lengths / e00),
        from_trajectory_J=finite(trajectory),
        from_trajectory_percent=finite(100.0 * trajectory / e00),
        interaction_J=finite(total - lengths - trajectory),
        total_J=finite(total),
    )


def write_results(out: Path, result: Result, arrays: dict[str, Array]) -> None:
    """Write ``result.json`` and ``trajectory.npz`` (its declared schema) atomically."""
    write_trajectory(out, arrays)
    write_atomic(out / RESULT_FILE, json.dumps(result.to_json(), indent=2) + "\n")


def multistart_summary(
    problem: Problem, results: list[SolveResult], tolerance: float, energy: Callable[[Array], float] | None = None
) -> MultiStart:
    """Whether every converged start reached the same Xi within ``tolerance`` [m]; else the distinct optima.

    A start whose solver failed is no optimum: it is left out of ``distinct_optima`` and listed
    under ``failed_starts`` with its message (its row has no optimal lengths or cost). ``energy``
    gives a design's net energy [J] (default: on the task's fine grid; a mix passes its own).
    """
    rows: list[StartRow] = []
    failed: list[FailedStart] = []
    for r in results:
        optimal, cost = None, None
        if r.success:
            ev = problem.evaluate(r.z)
            optimal = ev.lengths
            if isinstance(problem, LinkLengthProblem) and isinstance(ev, Evaluation):  # costf2 whatever the objective
                cost = SquaredPowerCost(problem.emlas, problem.dt).value(ev)
            else:  # a mix: its weighted cost
                cost = ev.cost
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
    if energy is None and len(results) > 1 and isinstance(problem, LinkLengthProblem):
        fine = fine_problem(problem)

        def energy(z: Array) -> float:
            return design_summary(fine, z).summary.net_electrical_energy_J

    by_start = {r.start: r for r in results}
    distinct = tuple(
        DistinctOptimum(
            xi=tuple(xi.tolist()),
            cost_W2s=cost,
            starts=tuple(starts),
            net_electrical_energy_J=None if energy is None or len(results) < 2 else energy(by_start[starts[0]].z),
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
    )


def tracking_bands(study: Study) -> TrackingBands:
    """The study's tracking tolerance bands as result.json's ``settings.tracking_bands``."""
    return TrackingBands(
        position_m=study.tracking.position,
        velocity_m_per_s=study.tracking.velocity,
        acceleration_m_per_s2=study.tracking.acceleration,
        collocation_fraction=study.tracking.collocation_fraction,
    )

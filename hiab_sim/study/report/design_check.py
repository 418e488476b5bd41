"""One task's design evaluated on a grid: energies, peaks, violations, re-check and the saving's decomposition.

Energies are integrated on the fine grid (``grid.fine_factor`` times the collocation grid, 10 by default): the
cost of eq. ``costf2`` is 1/2 Dt sum (sum_i P_i)^2 [W^2 s], a squared-power integral, not an energy, so the net
electrical energy (regeneration credited) and the energy drawn without regeneration are
reported separately, with the loss breakdown of :func:`hiab_sim.emla.operating_point`. Every
``cost_W2s`` here is costf2 whatever the study's objective (:func:`hiab_sim.study.nlp.objectives.costf2`).
:mod:`hiab_sim.study.report.result_folder` combines the tasks' sections into a result.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla import energy_summary, operating_point
from hiab_sim.errors import HiabSimError
from hiab_sim.quadrature import trapezoid
from hiab_sim.results.schema import (
    ENERGY_PARTS,
    ActuatorSummary,
    Decomposition,
    DecompositionDesign,
    DesignSummary,
    EnergyBreakdown,
    Recheck,
    TrackingBands,
    TrackingError,
    WorstConstraint,
)
from hiab_sim.study.motion.workspace import tracked_units
from hiab_sim.study.nlp.interface import bound_row_name
from hiab_sim.study.nlp.objectives import costf2
from hiab_sim.study.nlp.task_problem import XI_SCALE, Evaluation, TaskProblem
from hiab_sim.study.report.energy_section import cycle_battery_power
from hiab_sim.study.spec.study_file import Study


@dataclass(frozen=True)
class DesignCheck:
    """A design evaluated on the fine grid by one ID path, with its summary."""

    evaluation: Evaluation
    summary: DesignSummary

    @property
    def actuator_names(self) -> tuple[str, ...]:
        """The actuators, in the order of the evaluation's columns."""
        return tuple(self.summary.actuators)


def _extra_errors(problem: TaskProblem, errors: Array) -> dict[str, Any]:
    """The crane's telescope error [m], or a machine file's further tracked coordinates' by ``<name>_<unit>``."""
    if problem.study.crane_description is not None:
        return {"telescope_m": float(errors[0])}
    units = tracked_units(problem.model)[2:]
    names = problem.model.tracked_names[2:]
    return {
        "telescope_m": None,
        "tracked": {f"{n}_{u}": float(e) for n, u, e in zip(names, units, errors, strict=True)},
    }


def design_summary(problem: TaskProblem, z: Array) -> DesignCheck:
    """Evaluate z on ``problem``'s grid (the fine grid, nominal bands): energies, peaks, violations."""
    ev = problem.evaluate(z)
    t = problem.times
    act = ev.actuators
    net, drawn = energy_summary(t, ev.power.T)
    breakdown = np.zeros(len(ENERGY_PARTS))
    per_actuator: dict[str, ActuatorSummary] = {}
    for i, (name, params) in enumerate(zip(problem.emlas.names, problem.emlas, strict=True)):
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
        **_extra_errors(problem, np.max(np.abs(ev.tcp.position[:, 2:] - ref.position[:, 2:]), axis=0)),
    )
    summary = DesignSummary(
        lengths=ev.lengths,
        id_path=problem.id_path,
        grid_points=len(t),
        cost_W2s=costf2(problem.emlas, problem.dt).value(ev),
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


def worst_constraint(problem: TaskProblem, z: Array) -> WorstConstraint:
    """The constraint row or design-variable bound of least scaled margin at z (the rows first on a tie).

    The bounds count as :meth:`TaskProblem.max_violation` counts them: a design outside its bounds is
    named by the bound it crosses, not by a row that holds.
    """
    margins = problem.margins(z)
    names = list(problem.constraint_names)
    xi = np.asarray(z)[: problem.n_xi]
    for k, variable in enumerate(problem.model.design_names):
        low, up = problem.lower[k], problem.upper[k]
        margins = np.append(margins, [xi[k] - low, up - xi[k]])
        names += [bound_row_name(variable, "low", low * XI_SCALE), bound_row_name(variable, "up", up * XI_SCALE)]
    worst = int(np.argmin(margins))
    return WorstConstraint(names[worst], float(margins[worst]))


def fine_problem(problem: TaskProblem, id_path: str | None = None) -> TaskProblem:
    """The same study on the fine grid with nominal bands (for reports and the re-check)."""
    return TaskProblem(
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


def trajectory_arrays(fine: TaskProblem, checks: dict[str, DesignCheck]) -> dict[str, Array]:
    """``trajectory.npz``'s arrays of one task on its fine grid (SI units; a mix prefixes each task's keys)."""
    arrays: dict[str, Array] = {"time": fine.times, "reference_tcp": fine.reference.tcp()}
    arrays["payload_mass"] = fine.task.payload.mass_at(fine.times)  # the video draws it while held
    for name in ("initial", "optimal"):
        ev = checks[name].evaluation
        arrays[f"{name}_position"] = ev.joints.position
        arrays[f"{name}_velocity"] = ev.joints.velocity
        arrays[f"{name}_acceleration"] = ev.joints.acceleration
        arrays[f"{name}_tcp"] = fine.kin.position(ev.joints.position)
        arrays[f"{name}_actuator_force"] = ev.actuators.force
        arrays[f"{name}_actuator_velocity"] = ev.actuators.velocity
        arrays[f"{name}_actuator_stroke"] = ev.actuators.stroke
        arrays[f"{name}_electrical_power"] = ev.power
        arrays[f"{name}_battery_power"] = cycle_battery_power(fine, ev)
    return arrays


def recheck_section(checks: dict[str, DesignCheck], recheck: TaskProblem) -> Recheck:
    """The re-check section from the fine-grid checks (keys optimal, recheck_initial, recheck_optimal)."""
    rc = checks["recheck_optimal"].summary
    force_difference = np.abs(
        checks["optimal"].evaluation.actuators.force - checks["recheck_optimal"].evaluation.actuators.force
    )
    return Recheck(
        id_path=recheck.id_path,
        grid_points=len(recheck.times),
        note=f"optimal design re-evaluated on the {recheck.study.grid.fine_factor}x finer grid with the other ID path "
        "and nominal bands",
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


def energy_decomposition(problem: TaskProblem, fine: TaskProblem, z_initial: Array, z_optimal: Array) -> Decomposition:
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
            collocation_cost = costf2(problem.emlas, problem.dt).value(problem.evaluate(z))
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


def tracking_bands(study: Study) -> TrackingBands:
    """The study's tracking tolerance bands as result.json's ``settings.tracking_bands``."""
    return TrackingBands(
        position_m=study.tracking.position,
        velocity_m_per_s=study.tracking.velocity,
        acceleration_m_per_s2=study.tracking.acceleration,
        collocation_fraction=study.tracking.collocation_fraction,
    )


def task_checks(task: TaskProblem, z0: Array, z1: Array) -> tuple[dict[str, DesignCheck], TaskProblem, TaskProblem]:
    """The initial and optimal designs of one task on its fine grid and re-checked on the other ID path.

    Returns the checks (keys initial, optimal, recheck_initial, recheck_optimal), the fine problem
    and the re-check problem.
    """
    fine, recheck = fine_problem(task), fine_problem(task, other_path(task.id_path))
    checks = {
        "initial": design_summary(fine, z0),
        "optimal": design_summary(fine, z1),
        "recheck_initial": design_summary(recheck, z0),
        "recheck_optimal": design_summary(recheck, z1),
    }
    return checks, fine, recheck

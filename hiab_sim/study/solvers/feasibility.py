"""Feasibility phase: from a start that violates constraints to the nearest feasible point, or a named limit.

Least violation within the bounds: first minimise

    phi(z) = 1/2 sum_i min(0, g_i(z) - delta)^2 + 1/2 sum_j e_j(z)^2

over z with Xi in its bounds (L-BFGS-B with the problem's exact gradients, grad phi = J^T min(0,
g - delta) + E^T e), g the solver's scaled rows (tightened bands, clearances, robust rows) and
delta = :data:`TARGET` a small positive target. From that point SLSQP finds the feasible point
nearest to the start, min 1/2 |z - z0|^2 subject to every row (the penalty alone approaches the
feasible set only asymptotically and not along the shortest way). Where the penalty stalls far from
the feasible set (its gradient vanishes with the violation), SLSQP minimises the largest violation
v directly, g(z) + v >= 0 (:func:`_least_max_violation`), before the projection.
If the least violation stays > 0, no feasible point was found: :class:`InfeasibleStudyError`
names the row that is violated most at the best point, where and by how much in physical units
(:func:`describe_violation`). A trial point outside the model's domain (a chain that cannot close)
counts as a large phi, so the line search steps back.

A duty mix (:class:`~hiab_sim.study.nlp.problem.StudyProblem`: thousands of rows) runs the same phase with
the projection on IPOPT (sparse Jacobians, :func:`hiab_sim.study.solvers.ipopt.solve_ipopt` with the
distance as its objective): dense SLSQP costs seconds per iteration there. The direct
least-largest-violation step is dense SLSQP and serves single tasks only; where the penalty
stalls on a mix, the least violation it found is reported.
"""

from __future__ import annotations

import contextlib
import math

import numpy as np
from scipy.optimize import minimize

from hiab_sim.arrays import Array
from hiab_sim.errors import InfeasibleStudyError, InvalidInputError
from hiab_sim.results.analysis_sections import FeasibilityPhase
from hiab_sim.study.constraints.blocks import STROKE_SCALE
from hiab_sim.study.machines.protocol import Design
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers.ipopt import solve_ipopt
from hiab_sim.study.solvers.single_solve import run_slsqp, slsqp_bounds
from hiab_sim.study.solvers.slsqp import start_points

#: Scaled margin the phase aims for on every row.
TARGET = 1e-4
#: Violation [scaled] reported for every row at a trial point outside the model's domain.
OUTSIDE = 1e3
#: Least violation [scaled] below which the penalty's point is projected onto the feasible set by SLSQP.
POLISH = 1e-2
#: A start whose nominal rows are all >= -this needs no feasibility phase (round-off only).
START_TOLERANCE = 1e-9
#: Iteration limit of a mix's projection on IPOPT.
PROJECTION_ITERATIONS = 300
#: Rows within this [scaled] of the least violation count as violated as much (a least-largest violation ties them).
TIE = 1e-6
_REMEDY = {
    "peak_torque": "a larger motor or gear ratio is needed",
    "rated_speed": "a faster motor or a longer screw lead is needed",
    "voltage": "a higher bus voltage is needed",
}


def describe_violation(problem: StudyProblem, index: int, value: float) -> str:
    """A row's violation in words and physical units ("lift EMLA peak torque exceeded by 28 % at t = 2.5 s").

    A mix's rows are named ``<task>: <row>``; the task is said after the time.
    """
    task, _, name = problem.constraint_names[index].rpartition(": ")
    where = ""
    if " at t=" in name:
        name, t = name.split(" at t=")
        where = f" at t = {t}"
    if task:
        where += f" of task {task}"
    block = name.split(".")[0]
    if block == "envelope":
        _, actuator, limit = name.split(".")
        m = problem.envelope_margin
        g = value * (1.0 - m) + m
        excess = 100.0 * (math.sqrt(max(1.0 - g, 0.0)) - 1.0)
        if excess <= 0.0:
            return (
                f"{actuator} EMLA {limit.replace('_', ' ')} at {100.0 + excess:.1f} % of its limit{where}, inside the "
                f"envelope margin {m:g} the optimiser keeps: {_REMEDY.get(limit, 'a larger EMLA is needed')}"
            )
        return (
            f"{actuator} EMLA {limit.replace('_', ' ')} exceeded by {excess:.{0 if abs(excess) >= 10 else 1}f} %"
            f"{where}"
            f": {_REMEDY.get(limit, 'a larger EMLA is needed')}"
        )
    if block in ("stroke", "working_range", "buildable_range"):
        return f"{name}{where} violated by {-value * STROKE_SCALE * 1e3:.1f} mm"
    if block == "tracking":
        return f"{name}{where}: the TCP leaves its tracking band by {-value * 100:.0f} % of the band"
    # any other block (e.g. a registered one) states its rows' unit (ConstraintBlock.relaxation)
    stacked = next(b for b in problem.blocks if b.rows.start <= index < b.rows.stop)
    i = index - stacked.rows.start
    relax = stacked.block.relaxation(np.full(stacked.rows.stop - stacked.rows.start, value))
    unit, per_unit = relax.units[i], float(relax.per_unit[i])
    if per_unit > 0.0:
        return f"{name}{where} violated by {-value / per_unit:.3g} {unit}"
    return f"{name}{where} violated by {-value:.3g} (scaled)"


def describe_binding(problem: StudyProblem, g: Array) -> str:
    """The most violated row in words, then the most violated row of each other block violated as much.

    Minimising the largest violation spreads it over every row that competes for the same design: the
    limit that cannot be met (a winding temperature) ends tied with those it was traded against (the
    tracking band), so every tied block is named.
    """
    order = np.argsort(g, kind="stable")
    blocks: dict[str, int] = {}
    for k in order:
        if g[k] > g[order[0]] + TIE:
            break
        block = problem.constraint_names[k].rpartition(": ")[2].split(".")[0]
        blocks.setdefault(block, int(k))
    words = [describe_violation(problem, k, float(g[k])) for k in blocks.values()]
    return words[0] + "".join(f"; as far out: {w}" for w in words[1:])


def _phi(problem: StudyProblem, z: Array) -> tuple[float, Array]:
    try:
        g = problem.constraints(z)
        e = problem.equalities(z)
        short = np.minimum(0.0, g - TARGET)
        value = 0.5 * float(short @ short + e @ e)
        grad = problem.constraints_jacobian(z).T @ short + problem.equalities_jacobian(z).T @ e
    except InvalidInputError:
        return 1e10, np.zeros_like(z)
    return value, grad


def _project(
    problem: StudyProblem, target: Array, start: Array, bounds: list[tuple[float | None, float | None]]
) -> Array:
    """The point nearest to ``target`` that satisfies the rows to SLSQP's accuracy, searched from ``start``.

    With several tasks (thousands of rows) the same problem goes to IPOPT (sparse Jacobians); one
    task's goes to SLSQP.
    """
    target = np.array(target)
    if problem.n_tasks > 1:
        outcome = solve_ipopt(
            problem,
            np.array(start),
            PROJECTION_ITERATIONS,
            1e-12,
            objective=(lambda x: 0.5 * float((x - target) @ (x - target)), lambda x: x - target),
            constraint_tolerance=0.1 * START_TOLERANCE,  # the phase's point must pass check_start
        )
        return outcome.z
    res = minimize(
        lambda x: (0.5 * float((x - target) @ (x - target)), x - target),
        np.array(start),
        jac=True,
        method="SLSQP",
        bounds=bounds,
        constraints=[
            {"type": "ineq", "fun": problem.constraints, "jac": problem.constraints_jacobian},
            {"type": "eq", "fun": problem.equalities, "jac": problem.equalities_jacobian},
        ],
        options={"maxiter": 100, "ftol": 1e-14},
    )
    return np.asarray(res.x, dtype=float)


def _least_max_violation(
    problem: StudyProblem, z: Array, bounds: list[tuple[float | None, float | None]], maxiter: int
) -> Array:
    """Min v over (z, v) subject to g(z) + v >= 0, e(z) = 0, v >= -TARGET (SLSQP, exact gradients).

    One extra variable: the largest violation v. Unlike the squared penalty its gradient does not
    vanish as the violation shrinks, so it crosses long flat stretches (a payload that only a much
    longer lever arm can carry). Returns z at the least largest violation found (z itself if a
    trial point left the model's domain).
    """
    n = len(z)
    v0 = max(0.0, -float(problem.constraints(z).min())) + TARGET
    rows = len(problem.constraint_names)

    last = [np.hstack([problem.constraints_jacobian(z), np.ones((rows, 1))])]
    e0, E = problem.equalities(z), problem.equalities_jacobian(z)  # the rest equalities are affine in z

    def rows_plus_v(x: Array) -> Array:
        try:
            return problem.constraints(x[:n]) + x[n]
        except InvalidInputError:  # outside the model's domain: a large violation, so the line search steps back
            return np.full(rows, -OUTSIDE)

    def rows_jacobian(x: Array) -> Array:
        # Outside the model's domain the last Jacobian inside it is kept (the point is rejected anyway:
        # rows_value returns a large violation there).
        with contextlib.suppress(InvalidInputError):
            last[0] = np.hstack([problem.constraints_jacobian(x[:n]), np.ones((rows, 1))])
        return last[0]

    unit = np.zeros(n + 1)
    unit[n] = 1.0
    try:
        res = run_slsqp(
            lambda x: float(x[n]),
            lambda x: unit,
            np.append(z, v0),
            [*bounds, (-TARGET, None)],
            (lambda x: e0 + E @ (x[:n] - z), lambda x: np.hstack([E, np.zeros((E.shape[0], 1))])),
            (rows_plus_v, rows_jacobian),
            maxiter,
            1e-12,
        )
    except InvalidInputError:
        return z
    out = np.asarray(res.z[:n], dtype=float)
    try:
        better = problem.constraints(out).min() > problem.constraints(z).min()
    except InvalidInputError:  # SLSQP may end on a trial point outside the model's domain
        return z
    return out if better else z


def changes(before: Design, after: Design) -> tuple[str, ...]:
    """What the phase changed, one line per moved decision variable [mm], named as the design names it."""
    a, b = before.as_array(), after.as_array()
    return tuple(
        f"{n}: {x * 1e3:.1f} -> {y * 1e3:.1f} mm ({(y - x) * 1e3:+.1f} mm)"
        for n, x, y in zip(before.names, a, b, strict=True)
        if abs(y - x) > 1e-6
    )


def feasible_start(
    problem: StudyProblem, z0: Array, start: int = 0, maxiter: int = 500
) -> tuple[Array, FeasibilityPhase | None]:
    """The start itself if it is feasible, else the feasibility phase's point and what it changed.

    Raises:
        InfeasibleStudyError: the least violation within the bounds is > 0 (message: the binding limit).

    """
    z0 = np.asarray(z0, dtype=float)
    try:
        margins = problem.margins(z0)
        worst = int(np.argmin(margins))
        violation0 = max(0.0, -float(margins[worst]), float(np.abs(problem.equalities(z0)).max()))
        worst_name = problem.constraint_names[worst]
    except InvalidInputError as error:
        violation0, worst_name = math.inf, f"not an admissible crane: {error}"
    if violation0 <= START_TOLERANCE:
        return z0, None
    bounds = slsqp_bounds(problem.lower, problem.upper)
    res = minimize(
        lambda z: _phi(problem, z),
        z0,
        jac=True,
        method="L-BFGS-B",
        bounds=bounds,
        options={"maxiter": maxiter, "ftol": 1e-15, "gtol": 1e-12},
    )
    z = np.asarray(res.x, dtype=float)
    g = problem.constraints(z)
    if g.min() <= -POLISH and problem.n_tasks == 1:  # the penalty stalled far out (dense SLSQP: one task)
        z = _least_max_violation(problem, z, bounds, maxiter)  # minimise the largest violation directly
        g = problem.constraints(z)
    if g.min() > -POLISH:  # near or in the feasible set: the nearest feasible point to the start, else to z
        for target in (z0, z):
            try:
                candidate = _project(problem, target, z, bounds)
                if problem.constraints(candidate).min() >= -START_TOLERANCE:
                    z = candidate
                    break
            except InvalidInputError:
                continue
        g = problem.constraints(z)
    if g.min() < -START_TOLERANCE or np.abs(problem.equalities(z)).max() > 1e-9:
        xi = ", ".join(f"{v:.4f}" for v in problem.unpack(z)[0].as_array())
        raise InfeasibleStudyError(
            f"no feasible point within the bounds (feasibility phase from start {start}, least violation at "
            f"Xi = [{xi}] m): " + describe_binding(problem, g)
        )
    before, _ = problem.unpack(z0)
    after, _ = problem.unpack(z)
    return z, FeasibilityPhase(
        start=start,
        initial_max_violation=violation0,
        initial_worst=worst_name,
        final_max_violation=problem.max_violation(z),
        lengths_before=before,
        lengths_after=after,
        changes=changes(before, after) or ("only the trajectory (spline coefficients) changed",),
        iterations=int(res.nit),
    )


def feasible_starts(problem: StudyProblem, count: int, seed: int = 6) -> tuple[list[Array], list[FeasibilityPhase]]:
    """The study's start and ``count - 1`` starts drawn uniformly in the Xi bounds, each made feasible.

    A draw the feasibility phase cannot repair is skipped (at most 20 ``count`` draws); the
    study's own start raises :class:`InfeasibleStudyError` if it cannot be repaired.
    """
    z, phase = feasible_start(problem, problem.initial_point(problem.study.initial_lengths), 0)
    points, phases = [z], [phase] if phase else []
    if count > 1:
        # The solver's own draw of feasible starts (sensible retracted lengths for the working range);
        # where it finds fewer than ``count``, the uniform draws below fill in.
        try:
            drawn = start_points(problem, count, seed)[1:]
        except InvalidInputError:
            drawn = []
        points += [problem.initial_point(lengths) for lengths in drawn]
    rng = np.random.default_rng(seed)
    low, up = problem.lower[: problem.n_xi], problem.upper[: problem.n_xi]
    for _ in range(20 * count):
        if len(points) >= count:
            break
        xi = rng.uniform(low, up)
        try:
            z, phase = feasible_start(problem, problem.initial_point(problem.model.design(xi)), len(points))
        except InvalidInputError:
            continue
        points.append(z)
        if phase is not None:
            phases.append(phase)
    if len(points) < count:
        raise InvalidInputError("starts", count, f"only {len(points)} feasible starts found in the bounds")
    return points, phases


def phase_lines(phase: FeasibilityPhase) -> list[str]:
    """Lines for stdout: what the phase started from and what it changed."""
    return [
        f"feasibility phase (start {phase.start}): max violation {phase.initial_max_violation:.2e} "
        f"({phase.initial_worst}) -> {phase.final_max_violation:.1e} in {phase.iterations} iterations; changed:",
        *(f"  {c}" for c in phase.changes),
    ]


def moved_start_phase(problem: StudyProblem, z: Array) -> FeasibilityPhase | None:
    """The step that moved the study's start into the bounds, when the built crane's lengths lie outside them.

    The loader projects the built crane's lengths onto the bounds and re-centres each moved chain's
    retracted length on its stroke (:func:`hiab_sim.study.spec.study_file._clipped_lengths`): this records what
    that changed, like a feasibility phase (``iterations`` 0), so the run says it.
    """
    before = problem.study.start_moved_from
    if before is None:
        return None
    xi = before.as_array()
    low, up = problem.lower[: problem.n_xi], problem.upper[: problem.n_xi]
    excess = np.maximum(low - xi, xi - up)
    k = int(np.argmax(excess))
    return FeasibilityPhase(
        start=0,
        initial_max_violation=float(excess[k]),
        initial_worst=(
            f"bounds: the built machine's {problem.model.design_names[k]} lies "
            f"{excess[k] * 1e3:.1f} mm outside its bounds"
        ),
        final_max_violation=problem.max_violation(z),
        lengths_before=before,
        lengths_after=problem.study.initial_lengths,
        changes=changes(before, problem.study.initial_lengths),
        iterations=0,
    )

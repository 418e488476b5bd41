"""One solve by the study's method: the one call of scipy's SLSQP and the dispatch on ``solver.method``.

:func:`solve_once` minimises a study's scaled cost from a point by SLSQP or IPOPT with the given
iteration limit and tolerance; the study's solve (:func:`hiab_sim.study.solvers.slsqp.solve`: start
check, history, checkpoints) and each Pareto point (:func:`hiab_sim.sweep.pareto.solve_point`) call
it. :func:`run_slsqp` is the one call of SLSQP, also for problems that are not a study's own (the
Pareto front's least-criterion solve, whose epigraph variable t is not one of the study's), with the
bounds in scipy's form from :func:`slsqp_bounds`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.optimize import minimize

from hiab_sim.arrays import Array
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers.ipopt import solve_ipopt
from hiab_sim.study.solvers.outcome import Outcome
from hiab_sim.study.solvers.threads import single_blas_thread

#: A constraint function of z and its Jacobian (None: scipy's finite differences).
Rows = tuple[Callable[[Array], Array], Callable[[Array], Array] | None]


def slsqp_bounds(lower: Array, upper: Array) -> list[tuple[float | None, float | None]]:
    """Box bounds in scipy's form: (low, up) per variable, None where a bound is infinite."""
    return [
        (lo if np.isfinite(lo) else None, hi if np.isfinite(hi) else None) for lo, hi in zip(lower, upper, strict=True)
    ]


def run_slsqp(
    cost: Callable[[Array], float],
    gradient: Callable[[Array], Array] | None,
    z0: Array,
    bounds: list[tuple[float | None, float | None]],
    equalities: Rows,
    inequalities: Rows,
    maxiter: int,
    ftol: float,
    callback: Callable[[Array], None] | None = None,
) -> Outcome:
    """Minimise cost(z) by scipy's SLSQP s.t. equalities(z) = 0, inequalities(z) >= 0 and ``bounds``, from z0.

    The one call of SLSQP (the study's solve, a Pareto point, the least-criterion solve, the
    feasibility phase's least largest violation); ``callback`` gets each iterate after the start.
    The caller chooses the BLAS threads.
    """
    constraints = []
    for kind, (fun, jac) in (("eq", equalities), ("ineq", inequalities)):
        constraints.append({"type": kind, "fun": fun} | ({} if jac is None else {"jac": jac}))
    res = minimize(
        cost,
        z0,
        jac=gradient,
        method="SLSQP",
        bounds=bounds,
        constraints=constraints,
        callback=callback,
        options={"maxiter": maxiter, "ftol": ftol},
    )
    return Outcome(np.asarray(res.x, dtype=float), bool(res.success), int(res.status), str(res.message), int(res.nit))


def solve_once(
    problem: StudyProblem,
    z0: Array,
    maxiter: int,
    ftol: float,
    callback: Callable[[Array], None] | None = None,
    use_gradients: bool = True,
) -> Outcome:
    """Minimise the problem's scaled cost from z0 once, by the study's ``solver.method``; no start check.

    ``slsqp``: :func:`run_slsqp` with one BLAS thread; ``ipopt``: :func:`~hiab_sim.study.solvers.ipopt.solve_ipopt`
    with the study's ``lbfgs_history``. ``callback`` gets each iterate
    after the start; ``use_gradients`` False leaves SLSQP's derivatives to finite differences.
    A trial point outside the model's domain raises :class:`InvalidInputError` under SLSQP; IPOPT cuts
    its step back from it (and a failed solve's message names it, :mod:`hiab_sim.study.solvers.ipopt`).
    """
    settings = problem.study.solver
    if settings.method == "ipopt":
        seen: list[int] = []

        def on_iterate(x: Array) -> None:
            if seen and callback is not None:  # IPOPT's iteration 0 is the start
                callback(x)
            seen.append(1)

        return solve_ipopt(problem, z0, maxiter, ftol, on_iterate, history=settings.lbfgs_history)
    with single_blas_thread():  # small matrices: pooled BLAS threads only contend (solvers.threads)
        return run_slsqp(
            problem.cost,
            problem.cost_gradient if use_gradients else None,
            z0,
            slsqp_bounds(problem.lower, problem.upper),
            (problem.equalities, problem.equalities_jacobian if use_gradients else None),
            (problem.constraints, problem.constraints_jacobian if use_gradients else None),
            maxiter,
            ftol,
            callback,
        )

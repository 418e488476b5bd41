"""The ``solver`` section of a result (single-task and mix problems alike)."""

from __future__ import annotations

from hiab_sim.results.schema import SolverSummary
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers.slsqp import SolveResult

#: What each ``solver.method`` is, as result.json's ``solver.method`` says it.
SOLVER_METHODS = {
    "slsqp": "SLSQP (scipy.optimize.minimize) with exact-structure gradients",
    "ipopt": "IPOPT (CasADi) with sparse exact-structure Jacobians, L-BFGS Hessian",
}


def solver_summary(problem: StudyProblem, main: SolveResult, wall_time: float) -> SolverSummary:
    """The ``solver`` section of a result: the method, the main start's outcome and counts."""
    return SolverSummary(
        method=SOLVER_METHODS[problem.study.solver.method],
        id_path=problem.id_path,
        success=main.success,
        status=main.status,
        message=main.message,
        iterations=main.iterations,
        wall_time_s=main.wall_time,
        total_wall_time_s=wall_time,
        max_violation_scaled=problem.max_violation(main.z),
        function_evaluations=main.n_evaluations,
        gradient_evaluations=main.n_gradients,
    )

"""Interior-point backend for large NLPs: IPOPT (through CasADi) with sparse Jacobians.

Dense SLSQP solves a least-squares QP over the full (m, n) Jacobian at every iteration, O(m n^2):
for a duty mix (a few hundred variables, thousands of rows) that is seconds per iteration (measured in
``benchmarks/bench_duty_mix.py``). IPOPT factorises the sparse KKT system instead. The NLP's
Jacobian is sparse by structure: a per-sample row (:class:`~hiab_sim.study.nlp.PerSampleBlock`)
depends on Xi and on the k + 1 B-spline coefficients per joint whose support covers its sample,
another row (an integral, the working range) on Xi and its task's coefficients; rows of another
task never depend on a task's coefficients. :func:`jacobian_sparsity` builds that pattern from the
blocks; the values are the problem's exact-structure Jacobian at the pattern. The Hessian is the
limited-memory quasi-Newton approximation (L-BFGS), as SLSQP's BFGS.

The NLP is the problem's own: min cost(z) s.t. equalities(z) = 0, constraints(z) >= 0, Xi
bounds. CasADi is an optional dependency (``pip install casadi``, wheels include IPOPT and MUMPS).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse

from hiab_sim.errors import ConfigError
from hiab_sim.study.mix import Problem
from hiab_sim.study.nlp import N_XI, Array, PerSampleBlock
from hiab_sim.study.problem import LinkLengthProblem

#: IPOPT return states counted as converged.
SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
#: Consecutive iterations of cost change < tol (feasible) that end the solve.
ACCEPTABLE_ITERATIONS = 5


@dataclass
class IpoptOutcome:
    """What IPOPT returned: the point, success, status text, iterations and the iterates' z."""

    z: Array
    success: bool
    message: str
    iterations: int
    iterates: list[Array]


def task_sparsity(problem: LinkLengthProblem) -> sparse.csr_matrix:
    """Structural nonzeros of one task's constraint Jacobian (rows, 6 + 3 N) as a 0/1 matrix."""
    support = np.any(problem.B != 0.0, axis=0)  # (K, N): basis functions nonzero at each sample
    n_c = problem.basis.n
    rows: list[Array] = []
    for block in problem.layout.blocks:
        s = problem.layout.slices[block.name]
        count = s.stop - s.start
        if isinstance(block, PerSampleBlock):
            per = count // len(block.times)
            # the block's samples are the problem's samples (same grid)
            cols = np.concatenate([np.ones((len(block.times), N_XI), bool), np.tile(support, (1, 3))], axis=1)
            rows.append(np.repeat(cols, per, axis=0))
        else:
            rows.append(np.ones((count, N_XI + 3 * n_c), bool))
    return sparse.csr_matrix(np.vstack(rows).astype(float))


def jacobian_sparsity(problem: Problem) -> sparse.csr_matrix:
    """Structural nonzeros of D g/dz of a task's or a mix's NLP (module docstring)."""
    if isinstance(problem, LinkLengthProblem):
        return task_sparsity(problem)
    parts = []
    for k, (p, rows) in enumerate(zip(problem.problems, problem.rows, strict=True)):
        local = task_sparsity(p)[rows].tocoo()
        cols = np.where(local.col < N_XI, local.col, local.col - N_XI + problem.offsets[k])
        parts.append(sparse.csr_matrix((local.data, (local.row, cols)), shape=(len(rows), problem.n)))
    return sparse.csr_matrix(sparse.vstack(parts))


def _casadi() -> Any:
    try:
        import casadi
    except ImportError:  # an optional dependency
        raise ConfigError("solver.method: ipopt needs CasADi (pip install casadi)") from None
    return casadi


def solve_ipopt(
    problem: Problem, z0: Array, maxiter: int, tol: float, on_iterate: Callable[[Array], None] | None = None
) -> IpoptOutcome:
    """Minimise the problem's scaled cost from z0 with IPOPT (L-BFGS Hessian, sparse Jacobians).

    Args:
        problem: A task's or a mix's NLP.
        z0: Start point (scaled).
        maxiter: Iteration limit.
        tol: Relative cost change that ends the solve (as SLSQP's ``ftol``) once the point is
            feasible to 1e-8 (scaled); IPOPT's own ``tol`` on the scaled NLP error is 1e-8.
        on_iterate: Called with every iterate's z.

    """
    ca = _casadi()
    Base: Any = ca.Callback
    n = problem.n
    pattern = sparse.vstack([sparse.csr_matrix(problem.equalities_jacobian(z0) != 0.0), jacobian_sparsity(problem)])
    pattern = sparse.csc_matrix(pattern)
    pattern.sort_indices()
    m_eq = len(problem.equalities(z0))
    m = pattern.shape[0]
    jac_sparsity = ca.Sparsity(m, n, pattern.indptr.tolist(), pattern.indices.tolist())
    rows_csc = pattern.indices
    cols_csc = np.repeat(np.arange(n), np.diff(pattern.indptr))

    keep: list[Any] = []  # CasADi holds callbacks by reference: keep every one alive for the solve

    def g(z: Array) -> Array:
        return np.concatenate([problem.equalities(z), problem.constraints(z)])

    def jac_values(z: Array) -> Array:
        dense = np.vstack([problem.equalities_jacobian(z), problem.constraints_jacobian(z)])
        return dense[rows_csc, cols_csc]

    class JacG(Base):
        def __init__(self) -> None:
            ca.Callback.__init__(self)
            self.construct("jac_g", {})

        def get_n_in(self) -> int:
            return 2

        def get_n_out(self) -> int:
            return 1

        def get_sparsity_in(self, i: int) -> Any:
            return ca.Sparsity.dense(n, 1) if i == 0 else ca.Sparsity(m, 1)

        def get_sparsity_out(self, i: int) -> Any:
            return jac_sparsity

        def eval(self, arg: list[Any]) -> list[Any]:
            return [ca.DM(jac_sparsity, jac_values(np.asarray(arg[0]).ravel()))]

    class G(Base):
        def __init__(self) -> None:
            ca.Callback.__init__(self)
            self.construct("g", {"enable_fd": False})

        def get_n_in(self) -> int:
            return 1

        def get_n_out(self) -> int:
            return 1

        def get_sparsity_in(self, i: int) -> Any:
            return ca.Sparsity.dense(n, 1)

        def get_sparsity_out(self, i: int) -> Any:
            return ca.Sparsity.dense(m, 1)

        def eval(self, arg: list[Any]) -> list[Any]:
            return [g(np.asarray(arg[0]).ravel())]

        def has_jac_sparsity(self, oind: int, iind: int) -> bool:
            return True

        def get_jac_sparsity(self, oind: int, iind: int, symmetric: bool) -> Any:
            return jac_sparsity

        def has_jacobian(self) -> bool:
            return True

        def get_jacobian(self, name: str, inames: Any, onames: Any, opts: Any) -> Any:
            keep.append(JacG())
            return keep[-1]

    class GradF(Base):
        def __init__(self) -> None:
            ca.Callback.__init__(self)
            self.construct("grad_f", {})

        def get_n_in(self) -> int:
            return 2

        def get_n_out(self) -> int:
            return 1

        def get_sparsity_in(self, i: int) -> Any:
            return ca.Sparsity.dense(n, 1) if i == 0 else ca.Sparsity.dense(1, 1)

        def get_sparsity_out(self, i: int) -> Any:
            return ca.Sparsity.dense(1, n)

        def eval(self, arg: list[Any]) -> list[Any]:
            return [problem.cost_gradient(np.asarray(arg[0]).ravel())[None, :]]

    class F(Base):
        def __init__(self) -> None:
            ca.Callback.__init__(self)
            self.construct("f", {"enable_fd": False})

        def get_n_in(self) -> int:
            return 1

        def get_n_out(self) -> int:
            return 1

        def get_sparsity_in(self, i: int) -> Any:
            return ca.Sparsity.dense(n, 1)

        def get_sparsity_out(self, i: int) -> Any:
            return ca.Sparsity.dense(1, 1)

        def eval(self, arg: list[Any]) -> list[Any]:
            return [problem.cost(np.asarray(arg[0]).ravel())]

        def has_jacobian(self) -> bool:
            return True

        def get_jacobian(self, name: str, inames: Any, onames: Any, opts: Any) -> Any:
            keep.append(GradF())
            return keep[-1]

    iterates: list[Array] = []

    class Iteration(Base):
        def __init__(self, solver_outputs: int, sparsities: list[Any]) -> None:
            ca.Callback.__init__(self)
            self.outputs, self.sparsities = solver_outputs, sparsities
            self.construct("iteration", {})

        def get_n_in(self) -> int:
            return self.outputs

        def get_n_out(self) -> int:
            return 1

        def get_name_in(self, i: int) -> str:
            return str(ca.nlpsol_out(i))

        def get_sparsity_in(self, i: int) -> Any:
            return self.sparsities[i]

        def eval(self, arg: list[Any]) -> list[Any]:
            z = np.asarray(arg[0]).ravel().copy()
            iterates.append(z)
            if on_iterate is not None:
                on_iterate(z)
            return [0]

    f_cb, g_cb = F(), G()
    x = ca.MX.sym("z", n)
    nlp = {"x": x, "f": f_cb(x), "g": g_cb(x)}
    sizes = {"x": (n, 1), "f": (1, 1), "g": (m, 1), "lam_x": (n, 1), "lam_g": (m, 1), "lam_p": (0, 1)}
    sparsities = [ca.Sparsity.dense(*sizes[str(ca.nlpsol_out(i))]) for i in range(ca.nlpsol_n_out())]
    iteration = Iteration(ca.nlpsol_n_out(), sparsities)
    options = {
        "ipopt.hessian_approximation": "limited-memory",
        "ipopt.max_iter": int(maxiter),
        "ipopt.tol": 1e-8,
        "ipopt.constr_viol_tol": 1e-8,
        # SLSQP's criterion: stop once the cost changes by less than ``tol`` (relative) for
        # ACCEPTABLE_ITERATIONS iterations at a point feasible to 1e-8; the L-BFGS Hessian otherwise
        # spends tens of iterations driving the dual infeasibility down at a flat cost
        "ipopt.acceptable_obj_change_tol": float(tol),
        "ipopt.acceptable_iter": ACCEPTABLE_ITERATIONS,
        "ipopt.acceptable_tol": 1e-2,
        "ipopt.acceptable_constr_viol_tol": 1e-8,
        "ipopt.acceptable_compl_inf_tol": 1e-6,
        "ipopt.print_level": int(os.environ.get("HIAB_IPOPT_PRINT", "0")),
        "print_time": False,
        "iteration_callback": iteration,
    }
    solver = ca.nlpsol("solver", "ipopt", nlp, options)
    lbx = np.where(np.isfinite(problem.lower), problem.lower, -np.inf)
    ubx = np.where(np.isfinite(problem.upper), problem.upper, np.inf)
    lbg = np.zeros(m)
    ubg = np.concatenate([np.zeros(m_eq), np.full(m - m_eq, np.inf)])
    out = solver(x0=z0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
    stats = solver.stats()
    z = np.asarray(out["x"]).ravel()
    return IpoptOutcome(
        z=z,
        success=stats.get("return_status") in SUCCESS,
        message=str(stats.get("return_status", "")),
        iterations=int(stats.get("iter_count", len(iterates))),
        iterates=iterates,
    )

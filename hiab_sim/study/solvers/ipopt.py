"""Interior-point backend for large NLPs: IPOPT (through CasADi) with sparse Jacobians.

Dense SLSQP solves a least-squares QP over the full (m, n) Jacobian at every iteration, O(m n^2):
for a duty mix (a few hundred variables, thousands of rows) that is seconds per iteration (measured in
``benchmarks/bench_duty_mix.py``). IPOPT factorises the sparse KKT system instead. The NLP is the
problem's own: min cost(z) s.t. equalities(z) = 0, constraints(z) >= 0, Xi bounds, with range pairs
held as two-sided rows and the Jacobian's values at its structural pattern
(:mod:`hiab_sim.study.solvers.sparse_rows`), handed to CasADi through copy-free buffer callbacks. The
Hessian is the limited-memory quasi-Newton approximation (L-BFGS), as SLSQP's BFGS, from the last
``solver.lbfgs_history`` (step, gradient change) pairs: IPOPT's default 6 forgets the curvature of a
flat optimum and creeps along it (the excavator's digging study: 282 iterations); the excavator
studies keep 80 (89 iterations to the same point). CasADi is an optional dependency
(``pip install casadi``, wheels include IPOPT and MUMPS).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.errors import BackendUnavailableError, InvalidInputError
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers.outcome import Outcome
from hiab_sim.study.solvers.sparse_rows import SparseJacobian
from hiab_sim.study.solvers.threads import register_casadi_blas, single_blas_thread

#: IPOPT return states counted as converged.
SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
#: Consecutive iterations of cost change < tol (feasible) that end the solve.
ACCEPTABLE_ITERATIONS = 5


def _casadi() -> Any:
    try:
        import casadi
    except ImportError:  # an optional dependency
        raise BackendUnavailableError(
            "IPOPT (solver.method: ipopt, duty-mix cross-evaluation) needs CasADi: pip install 'hiab-sim[ipopt]'"
        ) from None
    register_casadi_blas()
    return casadi


def _callback_class(ca: Any, failures: list[str]) -> Any:
    """A CasADi Callback whose outputs a numpy function computes from input 0, copy-free.

    A point outside the model's domain (:class:`InvalidInputError` from the model, e.g. a chain that
    cannot close at a trial design) is an evaluation error IPOPT handles itself (it cuts the step
    back): the callback returns failure instead of raising, so CasADi prints no Python traceback,
    and appends the error to ``failures``, which the solve's message reports when it fails.

    ``eval_buffer`` hands the inputs' and outputs' nonzeros as memoryviews (column-major): no DM is
    built per call (a 200k-nonzero DM from numpy costs ~15 ms). ``fill(z)`` returns one value per
    output (an output CasADi does not ask for is skipped). ``jacobian`` (optional) builds the
    Callback that is this one's Jacobian, ``jac_sparsity`` its structure: CasADi asks for them when
    it builds the NLP's derivative functions, whether or not IPOPT evaluates them.
    """
    Base: Any = ca.Callback

    class NumpyCallback(Base):
        def __init__(
            self,
            name: str,
            inputs: list[Any],
            outputs: list[Any],
            fill: Callable[[Array], tuple[Array | float, ...]],
            names_in: list[str] | None = None,
            names_out: list[str] | None = None,
            jacobian: Callable[[], Any] | None = None,
            jac_sparsity: Any = None,
        ) -> None:
            ca.Callback.__init__(self)
            self.inputs, self.outputs, self.fill = inputs, outputs, fill
            self.names_in, self.names_out = names_in, names_out
            self.jacobian, self.jac_sparsity = jacobian, jac_sparsity
            self.construct(name, {} if jacobian is None else {"enable_fd": False})

        def get_n_in(self) -> int:
            return len(self.inputs)

        def get_n_out(self) -> int:
            return len(self.outputs)

        def get_name_in(self, i: int) -> str:
            return self.names_in[i] if self.names_in is not None else f"i{i}"

        def get_name_out(self, i: int) -> str:
            return self.names_out[i] if self.names_out is not None else f"o{i}"

        def get_sparsity_in(self, i: int) -> Any:
            return self.inputs[i]

        def get_sparsity_out(self, i: int) -> Any:
            return self.outputs[i]

        def has_eval_buffer(self) -> bool:
            return True

        def eval_buffer(self, arg: Any, res: Any) -> int:
            z = np.frombuffer(arg[0], dtype=np.float64)
            try:
                values = self.fill(z.copy())
            except InvalidInputError as error:
                failures.append(str(error))
                return 1
            for buffer, value in zip(res, values, strict=True):
                if buffer is not None:
                    np.frombuffer(buffer, dtype=np.float64)[:] = value
            return 0

        def has_jacobian(self) -> bool:
            return self.jacobian is not None

        def get_jacobian(self, name: str, inames: Any, onames: Any, opts: Any) -> Any:
            assert self.jacobian is not None
            return self.jacobian()

        def has_jac_sparsity(self, oind: int, iind: int) -> bool:
            return self.jac_sparsity is not None

        def get_jac_sparsity(self, oind: int, iind: int, symmetric: bool) -> Any:
            return self.jac_sparsity

    return NumpyCallback


def solve_ipopt(
    problem: StudyProblem,
    z0: Array,
    maxiter: int,
    tol: float,
    on_iterate: Callable[[Array], None] | None = None,
    objective: tuple[Callable[[Array], float], Callable[[Array], Array]] | None = None,
    constraint_tolerance: float = 1e-8,
    history: int = 6,
) -> Outcome:
    """Minimise the problem's scaled cost from z0 with IPOPT (L-BFGS Hessian, sparse Jacobians).

    Args:
        problem: The study's NLP (one task or several).
        z0: Start point (scaled).
        maxiter: Iteration limit.
        tol: Relative cost change that ends the solve (as SLSQP's ``ftol``) once the point is
            feasible to 1e-8 (scaled); IPOPT's own ``tol`` on the scaled NLP error is 1e-8.
        on_iterate: Called with every iterate's z.
        objective: (value, gradient) of another objective over the problem's rows and bounds
            (the feasibility phase's distance to a point); default the problem's scaled cost.
        constraint_tolerance: Largest scaled row violation IPOPT may end with (its ``constr_viol_tol``).
        history: Pairs the L-BFGS Hessian keeps (``solver.lbfgs_history``; IPOPT's default 6).

    """
    cost, cost_gradient = (problem.cost, problem.cost_gradient) if objective is None else objective
    ca = _casadi()
    failures: list[str] = []
    Callback = _callback_class(ca, failures)
    n = problem.n
    jac = SparseJacobian(problem, z0)
    m = jac.shape[0]
    jac_sparsity = ca.Sparsity(m, n, jac.indptr.tolist(), jac.indices.tolist())
    dense_z = ca.Sparsity.dense(n, 1)
    keep: list[Any] = []  # CasADi holds callbacks by reference: keep every one alive for the solve

    def made(callback: Any) -> Any:
        keep.append(callback)
        return callback

    scalar, no_p = ca.Sparsity.dense(1, 1), ca.Sparsity.dense(0, 1)

    def derivative(name: str, output: Any, sparsity: Any, values: Callable[[Array], Array]) -> Callable[[], Any]:
        """The Callback of a Jacobian (inputs z and the nominal output) for CasADi's symbolic derivatives."""
        return lambda: made(Callback(name, [dense_z, output], [sparsity], lambda z: (values(z),)))

    f_cb = made(
        Callback(
            "f", [dense_z], [scalar], lambda z: (cost(z),), jacobian=derivative("df", scalar, dense_z.T, cost_gradient)
        )
    )
    g_out = ca.Sparsity.dense(m, 1)
    g_jacobian = derivative("dg", ca.Sparsity(m, 1), jac_sparsity, jac.values)
    g_cb = made(
        Callback("g", [dense_z], [g_out], lambda z: (jac.rows(z),), jacobian=g_jacobian, jac_sparsity=jac_sparsity)
    )
    # IPOPT's gradient and Jacobian functions given to CasADi whole (its options grad_f, jac_g): built
    # from the callbacks above, CasADi's Jacobian called dg once per 64 of the n columns (7 times here)
    grad_f = made(
        Callback(
            "grad_f",
            [dense_z, no_p],
            [scalar, dense_z],
            lambda z: (cost(z), cost_gradient(z)),
            ["x", "p"],
            ["f", "grad_f_x"],
        )
    )
    jac_g = made(
        Callback(
            "jac_g",
            [dense_z, no_p],
            [g_out, jac_sparsity],
            lambda z: (jac.rows(z), jac.values(z)),
            ["x", "p"],
            ["g", "jac_g_x"],
        )
    )

    iterates = [0]  # IPOPT's iterations so far (its iteration 0, the start, included)

    def record(z: Array) -> tuple[float]:
        iterates[0] += 1
        if on_iterate is not None:
            on_iterate(z)
        return (0.0,)

    sizes = {"x": (n, 1), "f": (1, 1), "g": (m, 1), "lam_x": (n, 1), "lam_g": (m, 1), "lam_p": (0, 1)}
    names = [str(ca.nlpsol_out(i)) for i in range(ca.nlpsol_n_out())]
    iteration = made(
        Callback("iteration", [ca.Sparsity.dense(*sizes[s]) for s in names], [scalar], record, names_in=names)
    )
    x = ca.MX.sym("z", n)
    nlp = {"x": x, "f": f_cb(x), "g": g_cb(x)}
    options = {
        "ipopt.hessian_approximation": "limited-memory",
        # the L-BFGS matrix's low-rank part goes into the factorised KKT system ("extended") rather
        # than 2 x history extra back-solves per iteration (Sherman-Morrison): ~25 % less wall time
        # on the duty mix at the same iterates' quality (benchmarks/bench_duty_mix.py)
        "ipopt.limited_memory_aug_solver": "extended",
        "ipopt.limited_memory_max_history": int(history),
        "ipopt.max_iter": int(maxiter),
        "ipopt.tol": 1e-8,
        "ipopt.constr_viol_tol": constraint_tolerance,
        # SLSQP's criterion: stop once the cost changes by less than ``tol`` (relative) for
        # ACCEPTABLE_ITERATIONS iterations at a point feasible to 1e-8; the L-BFGS Hessian otherwise
        # spends tens of iterations driving the dual infeasibility down at a flat cost
        "ipopt.acceptable_obj_change_tol": float(tol),
        "ipopt.acceptable_iter": ACCEPTABLE_ITERATIONS,
        "ipopt.acceptable_tol": 1e-2,
        "ipopt.acceptable_constr_viol_tol": constraint_tolerance,
        "ipopt.acceptable_compl_inf_tol": 1e-6,
        "ipopt.print_level": int(os.environ.get("HIAB_IPOPT_PRINT", "0")),
        "ipopt.sb": "yes",  # no licence banner on stdout (it broke --quiet and the answer-first console)
        "ipopt.print_timing_statistics": "yes" if os.environ.get("HIAB_IPOPT_PRINT") else "no",
        "print_time": False,
        "iteration_callback": iteration,
        "grad_f": grad_f,
        "jac_g": jac_g,
    }
    solver = ca.nlpsol("solver", "ipopt", nlp, options)
    lbx = np.where(np.isfinite(problem.lower), problem.lower, -np.inf)
    ubx = np.where(np.isfinite(problem.upper), problem.upper, np.inf)
    lbg = np.zeros(m)
    ubg = jac.upper(z0)
    # every BLAS on one thread, CasADi's own OpenBLAS under MUMPS included (loaded with the plugin
    # above): IPOPT's iterates then do not depend on the core count (:mod:`hiab_sim.study.solvers.threads`)
    # each task's Jacobian written into one buffer, point after point: IPOPT gathers its nonzeros at once
    # (SparseJacobian.values) and no (m, n) array is allocated per point; the problems own theirs again after
    for t in jac.tasks:
        t.problem.jacobian_buffer = np.zeros((len(t.problem.constraint_names), t.problem.n))
    try:
        with single_blas_thread():
            out = solver(x0=z0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
    finally:  # (the last point's cached Jacobian stays the buffer, which nothing writes again)
        for t in jac.tasks:
            t.problem.jacobian_buffer = None
    stats = solver.stats()
    z = np.asarray(out["x"]).ravel()
    success = stats.get("return_status") in SUCCESS
    message = str(stats.get("return_status", ""))
    if failures and not success:
        message += f" ({len(failures)} trial point(s) outside the model's domain; the last: {failures[-1]})"
    return Outcome(z, success, 0 if success else 1, message, int(stats.get("iter_count", iterates[0])))

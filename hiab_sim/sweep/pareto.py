"""Pareto front of the study's objective against a second criterion, by the epsilon-constraint method.

Each front point minimises the study's objective (any registered one,
:data:`hiab_sim.study.nlp.objectives.OBJECTIVES`; for a duty mix the weighted sum over its tasks,
:class:`hiab_sim.study.nlp.problem.StudyProblem`) subject to every constraint of every task and one
more, criterion(z) <= epsilon, where the criterion is the worst over the tasks:

* ``peak_force``: max over the tasks, their collocation samples and the actuators of |f_x| [N],
  as the rows epsilon - f_x >= 0 and epsilon + f_x >= 0 per task, sample and actuator (smooth);
* ``rms_torque``: max over the tasks of sqrt(mean_k sum_i tau_m,i(t_k)^2) [N m], the motor torques
  of eq. ``torque_torque`` at the task's collocation samples (a proxy of the motors' thermal load),
  one row epsilon - rms_j >= 0 per task j.

The epsilon rows are one more constraint block per task (:mod:`hiab_sim.sweep.epsilon_rows`): their
values read each task's own inverse dynamics on its machine (crane file or machine file alike), their
Jacobian its ID partials chained through the B-spline matrices like every other row, and each front
point is solved by the study's own method with its settings (:func:`solve_point`: SLSQP dense, or
IPOPT with the sparse pattern the blocks give). The criterion functions below
(:func:`criterion_samples`, :func:`samples_jacobian`) compute the same quantities on their own, for
the least-criterion solve and the reported criterion: the forces f_x, or the motor torques of eq.
``torque_torque`` (:func:`hiab_sim.emla.drive.drive_state`), their Jacobian chained exactly through
the B-spline matrices from the per-sample ID partials (central differences in q9,
:func:`hiab_sim.study.nlp.id_partials.id_joint_partials`, and in Xi, ``StudyMachine.design_partials``)
and the motor torque's analytic partials.

The front's epsilon runs from the plain optimum's criterion c_0 (epsilon inactive: the plain study)
down to the least criterion c_min the constraints allow (:func:`minimise_criterion`, the epigraph
form min t s.t. -t <= s_k <= t, dense SLSQP whatever the study's method: the extra variable t is not
one of the study's), equally spaced, so every epsilon is feasible. Each point starts from the
previous one; if that fails, from the study's start, then from the c_min design z_min; a point
tried from more than one start keeps each try's message (``from the previous point: ...; from the
study's start: ...``). The study's start is the plain optimisation's, which IPOPT can evaluate:
IPOPT first moves a start lying on a bound inside by up to 1 % of the variable's range (its
bound_push and bound_frac), and from a design on a bound where the working range binds that can
leave the model's domain (measured on the XS 031 test study: the warm start fails at its first
evaluation). z_min is feasible for every epsilon
>= c_min, but it is not the far end's answer: it minimises the criterion alone, and where several
designs reach c_min (only the samples at the peak fix it) it need not have the least objective among
them (measured: the grading study's z_min 0.9543 of its start's objective, its far end 0.9460; the
XS 031 test study's 0.9252 and 0.9230 at the least criterion itself). So the far end is solved like every
point, and reported not converged if it fails. Its epsilon stands :data:`FAR_END_SLACK` of the span
c_0 - c_min above c_min, not at c_min: there the feasible set is the designs reaching the least
criterion only, and the epsilon rows active at the peak samples are the same rows that fixed c_min,
so no point strictly inside them exists and SLSQP's line search stalls (measured on the default
study: 79 iterations, "Positive directional derivative for linesearch", from each of the three
starts; 0.1 % of the span above it, 7 iterations from z_min). The least-criterion design itself is
returned beside the front (:class:`Front`), so c_min and its design's objective are reported too.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla.drive import drive_state
from hiab_sim.errors import InvalidInputError, SolverError
from hiab_sim.study.nlp.objectives import costf2
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import C_SCALE, XI_SCALE, TaskProblem
from hiab_sim.study.solvers.single_solve import run_slsqp, slsqp_bounds, solve_once
from hiab_sim.study.solvers.threads import single_blas_thread
from hiab_sim.sweep.epsilon_rows import epsilon_problem

CRITERIA = {"peak_force": "N", "rms_torque": "N m"}
#: Largest scaled violation (study rows and epsilon rows) of an accepted front point.
FEASIBLE = 1e-6
#: Iteration limit of the least-criterion solve (the front's far end), a multiple of the study's ``solver.maxiter``.
#: Its epigraph form min t s.t. -t <= s_k(z) <= t brings the samples near the peak into the active set a
#: few per iteration, so it takes more iterations than the study's own NLP: the default study's peak
#: force needs 124 SLSQP iterations to its KKT point (maxiter 100), its front points 8-19.
CRITERION_MAXITER_FACTOR = 4
#: Where the front's far end stands above the least criterion, a fraction of the span c_0 - c_min (module
#: docstring): small enough to be c_min to the criterion's reported digits on the shipped studies (0.1 N
#: of the default study's 103 N span), large enough for the epsilon rows to leave the solver an interior.
#: Measured on the default study's far end from z_min: 1e-4 fails (40 iterations), 1e-3 converges in 7.
FAR_END_SLACK = 1e-3


def _check_name(name: str) -> None:
    if name not in CRITERIA:
        raise InvalidInputError("--against", name, f"must be one of {', '.join(CRITERIA)}")


def task_samples(p: TaskProblem, zk: Array, name: str, jacobian: bool = False) -> tuple[Array, Array | None]:
    """What the criterion bounds on one task at its own z: forces f_x (K A,) [N] or its rms torque (1,) [N m].

    With ``jacobian`` also their partials w.r.t. the task's z = [z_xi, z_c], (S, n_xi + n_c).
    Forces are sample-major (row k A + i: sample k, actuator i), as the NLP's own actuator samples.
    """
    _check_name(name)
    design, c = p.unpack(zk)
    joints = p.joints(c)
    samples = JointSamples(joints.position, joints.velocity, joints.acceleration)
    model = p.model.inverse_dynamics(design, p.id_path)
    act = model(samples, tcp_force=p.tcp_force)
    K, A = act.force.shape
    n, n_xi = p.n_joints, p.n_xi
    drives = []
    if name == "peak_force":
        s = act.force.ravel()
    else:
        drives = [
            drive_state(e, act.force[:, i], act.velocity[:, i], act.acceleration[:, i]) for i, e in enumerate(p.emlas)
        ]
        tau = np.column_stack([d.motor_torque for d in drives])
        s = np.array([np.sqrt(np.mean(np.sum(tau**2, axis=1)))])
    if not jacobian:
        return s, None
    id_q = p.joint_partials(design, samples)  # (K, 3 A outputs (f, v, a), 3 n)
    id_xi = p.model.design_partials(design, samples, p.xi_path, p.fd_step, p.tcp_force)  # (K, 3 A, n_xi)
    if name == "peak_force":  # q9 index = order * n + joint; B (3 orders, K, N)
        dc = np.einsum("kaoj,okm->kajm", id_q[:, :A].reshape(K, A, 3, n), p.B) * C_SCALE
        return s, np.hstack([id_xi[:, :A].reshape(K * A, n_xi) * XI_SCALE, dc.reshape(K * A, p.n_c)])
    # d rms / d tau_ki = tau_ki / (K rms); tau_ki depends on (f, v, a) of actuator i at sample k only
    w = tau / (K * max(float(s[0]), 1e-300))
    g = np.zeros((K, 3 * A))
    for i, d in enumerate(drives):
        df, dv, da = d.d_motor_torque
        g[:, i], g[:, A + i], g[:, 2 * A + i] = w[:, i] * df, w[:, i] * dv, w[:, i] * da
    dq9 = np.einsum("ky,kyq->kq", g, id_q)
    dc = np.einsum("koj,okm->jm", dq9.reshape(K, 3, n), p.B) * C_SCALE
    dxi = np.einsum("ky,kyx->x", g, id_xi) * XI_SCALE
    return s, np.concatenate([dxi, dc.ravel()])[None]


def criterion_samples(problem: StudyProblem, z: Array, name: str) -> Array:
    """What the criterion bounds at z, every task's in task order: forces f_x [N] or each task's rms torque [N m]."""
    z = np.asarray(z, dtype=float)
    return np.concatenate([task_samples(p, problem.task_z(z, k), name)[0] for k, p in enumerate(problem.problems)])


def samples_jacobian(problem: StudyProblem, z: Array, name: str) -> Array:
    """D samples / dz (S, n): each task's rows in the Xi columns and its own coefficient columns."""
    z = np.asarray(z, dtype=float)
    parts = []
    for k, p in enumerate(problem.problems):
        jac = task_samples(p, problem.task_z(z, k), name, jacobian=True)[1]
        assert jac is not None
        out = np.zeros((len(jac), problem.n))
        off = problem.offsets[k]
        out[:, : problem.n_xi] = jac[:, : problem.n_xi]
        out[:, off : off + p.n_c] = jac[:, problem.n_xi :]
        parts.append(out)
    return np.vstack(parts)


def criterion(problem: StudyProblem, z: Array, name: str) -> float:
    """The criterion's value at z, the worst over the tasks [N or N m]."""
    return float(np.max(np.abs(criterion_samples(problem, z, name))))


def solve_point(problem: StudyProblem, z0: Array) -> tuple[Array, bool, str, int]:
    """Minimise the cost from z0 (need not be feasible) by the study's method: (z, accepted, message, iterations).

    The study's ``solver`` settings as :func:`hiab_sim.study.solvers.slsqp.solve` uses them: ``method``
    (``slsqp``: scipy's dense SLSQP; ``ipopt``: IPOPT with the blocks' sparse Jacobian and an L-BFGS
    Hessian of ``lbfgs_history`` pairs), ``maxiter`` and ``ftol``; one BLAS thread. That function
    checks that its start is feasible: a front point starts from the previous point, which its
    tighter epsilon cuts off. Accepted: the solver reports success and the point holds every row
    (epsilon rows included) to :data:`FEASIBLE`.
    """
    settings = problem.study.solver
    z0 = np.asarray(z0, dtype=float)
    try:
        with single_blas_thread():
            outcome = solve_once(problem, z0, settings.maxiter, settings.ftol)
    except InvalidInputError as error:  # a trial point left the model's domain
        return z0, False, f"a trial point left the model's domain: {error}", 0
    z = outcome.z
    return z, outcome.success and problem.max_violation(z) <= FEASIBLE, outcome.message, outcome.iterations


@dataclass(frozen=True)
class FrontPoint:
    """One point of the front: epsilon, the criterion reached, costf2 [W^2 s], the objective, status.

    ``objective_value`` is the study's objective [``objective_unit``: J for battery_energy, W^2 s
    for costf2; for a duty mix the weighted sum over its tasks], ``objective`` the same divided by
    its value at the study's start; ``costf2_W2s`` the paper's squared-power cost, weighted likewise,
    whatever the objective. ``xi`` are the machine's decision variables ``design_names`` [m].
    """

    epsilon: float
    criterion: float
    costf2_W2s: float
    objective_value: float
    objective_unit: str
    objective: float
    xi: tuple[float, ...]
    accepted: bool
    message: str
    iterations: int
    design_names: tuple[str, ...] = ()
    z: tuple[float, ...] = ()  # the point's scaled NLP variables (not a table column)

    def as_row(self) -> dict[str, Any]:
        """A table row."""
        row: dict[str, Any] = {
            k: getattr(self, k)
            for k in ("epsilon", "criterion", "costf2_W2s", "objective_value", "objective_unit", "objective")
        }
        names = self.design_names or tuple(f"xi_{k}" for k in range(len(self.xi)))
        row.update({f"{name}_m": v for name, v in zip(names, self.xi, strict=True)})
        row.update(accepted=self.accepted, message=self.message, iterations=self.iterations)
        return row


def minimise_criterion(problem: StudyProblem, z0: Array, name: str) -> tuple[Array, float, bool]:
    """The least criterion the study's constraints allow: min t s.t. -t <= s_k(z) <= t (epigraph form).

    Returns (z, c_min, converged); variables (z, t) with t scaled by the criterion at z0; SLSQP
    with :data:`CRITERION_MAXITER_FACTOR` times the study's iteration limit.
    """
    p = problem
    scale = max(criterion(p, z0, name), 1e-300)
    n = len(z0)

    def rows(x: Array) -> Array:
        s = criterion_samples(p, x[:n], name) / scale
        return np.concatenate([x[n] - s, x[n] + s])

    def rows_jacobian(x: Array) -> Array:
        d = samples_jacobian(p, x[:n], name) / scale
        return np.hstack([np.vstack([-d, d]), np.ones((2 * d.shape[0], 1))])

    def ineq(x: Array) -> Array:
        return np.concatenate([p.constraints(x[:n]), rows(x)])

    def ineq_jacobian(x: Array) -> Array:
        top = np.hstack([p.constraints_jacobian(x[:n]), np.zeros((len(p.constraint_names), 1))])
        return np.vstack([top, rows_jacobian(x)])

    zeros = np.zeros((len(p.equality_names), 1))
    res = run_slsqp(
        lambda x: x[n],
        lambda x: np.eye(n + 1)[n],
        np.append(np.asarray(z0, dtype=float), 1.0),
        [*slsqp_bounds(p.lower, p.upper), (0.0, None)],
        (lambda x: p.equalities(x[:n]), lambda x: np.hstack([p.equalities_jacobian(x[:n]), zeros])),
        (ineq, ineq_jacobian),
        CRITERION_MAXITER_FACTOR * p.study.solver.maxiter,
        p.study.solver.ftol,
    )
    z = res.z[:n]
    return z, criterion(p, z, name), res.success and p.max_violation(z) <= FEASIBLE


@dataclass(frozen=True)
class Front:
    """A traced front: its points from the plain optimum to the far end, and the least-criterion design.

    ``least`` is z_min (:func:`minimise_criterion`) as a point whose epsilon and criterion are c_min: the
    least criterion the study's constraints allow, at a design that minimises the criterion alone.
    """

    points: list[FrontPoint]
    least: FrontPoint


def pareto_front(problem: StudyProblem, z_optimum: Array, name: str, points: int) -> Front:
    """The front from the plain optimum (epsilon = its criterion c_0) to the least criterion c_min.

    Args:
        problem: The study's NLP (one task or many).
        z_optimum: The plain study's optimum (scaled z), e.g. from :func:`hiab_sim.study.solvers.slsqp.solve`.
        name: ``peak_force`` or ``rms_torque``.
        points: Number of epsilon values (>= 2), equally spaced from c_0 to the far end
            c_min + :data:`FAR_END_SLACK` (c_0 - c_min).

    """
    if points < 2:
        raise InvalidInputError("--points", points, "must be >= 2")
    _check_name(name)
    c0 = criterion(problem, z_optimum, name)
    z_min, c_min, converged = minimise_criterion(problem, z_optimum, name)
    if not converged:
        raise SolverError(f"minimising {name} subject to the study's constraints did not converge")
    front = [_point(problem, z_optimum, name, c0, True, "the plain optimum (epsilon inactive)", 0)]
    z = z_optimum
    z_start = problem.initial_point(problem.study.initial_lengths)
    least = _point(
        problem, z_min, name, c_min, True, "the least-criterion design (it minimises the criterion alone)", 0
    )
    for epsilon in np.linspace(c0, c_min + FAR_END_SLACK * (c0 - c_min), points)[1:]:
        bounded = epsilon_problem(problem, name, float(epsilon), c0)
        tried = []
        for start, label in (
            (z, "the previous point"),
            (z_start, "the study's start"),
            (z_min, "the least-criterion design"),
        ):
            z_new, accepted, message, iterations = solve_point(bounded, start)  # the first accepted ends it
            tried.append(f"from {label}: {message}")
            if accepted:
                break
        message = message if len(tried) == 1 else "; ".join(tried)
        front.append(_point(problem, z_new, name, float(epsilon), accepted, message, iterations))
        if accepted:
            z = z_new
    return Front(front, least)


def _point(
    problem: StudyProblem, z: Array, name: str, epsilon: float, accepted: bool, message: str, iterations: int
) -> FrontPoint:
    ev = problem.evaluate(z)
    return FrontPoint(
        epsilon,
        criterion(problem, z, name),
        sum(
            w * costf2(p.emlas, p.dt).value(t)
            for w, p, t in zip(problem.weights, problem.problems, ev.tasks, strict=True)
        ),
        ev.cost,
        problem.objective.unit,
        ev.cost / problem.cost_scale,
        tuple(float(v) for v in ev.lengths.as_array()),
        accepted,
        message,
        iterations,
        tuple(problem.model.design_names),
        tuple(float(v) for v in z),
    )


#: The criteria in words, for the front's axes and answer.
CRITERION_AXIS = {"peak_force": "peak actuator force", "rms_torque": "rms motor torque"}

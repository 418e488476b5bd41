"""Pareto front of the study's objective against a second criterion, by the epsilon-constraint method.

Each front point minimises the objective of eq. ``costf2`` subject to every constraint of the study
and one more, criterion(z) <= epsilon:

* ``peak_force``: max over the collocation samples and the three actuators of |f_x| [N], as the
  rows epsilon - f_x >= 0 and epsilon + f_x >= 0 per sample and actuator (smooth);
* ``rms_torque``: sqrt(mean_k sum_i tau_m,i(t_k)^2) [N m], the motor torques of eq.
  ``torque_torque`` at the collocation samples (a proxy of the motors' thermal load).

The epsilon rows are appended to the NLP's own rows (:class:`EpsilonProblem` wraps a
:class:`~hiab_sim.study.nlp.task_problem.TaskProblem` through its public methods); their Jacobian is
by central differences in z. The front's epsilon runs from the plain optimum's criterion c_0
(epsilon inactive: the plain study) down to the least criterion c_min the constraints allow
(:func:`minimise_criterion`, the epigraph form min t s.t. -t <= s_k <= t), equally spaced, so
every epsilon is feasible; each point is warm-started from the previous one (or from the
c_min design if that fails).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.emla.drive import drive_state
from hiab_sim.errors import InvalidInputError, SolverError
from hiab_sim.study.nlp.objectives import costf2
from hiab_sim.study.nlp.task_problem import C_SCALE, XI_SCALE, TaskProblem
from hiab_sim.style import colour

Array = NDArray[np.float64]
CRITERIA = {"peak_force": "N", "rms_torque": "N m"}
#: Largest scaled violation (study rows and epsilon rows) of an accepted front point.
FEASIBLE = 1e-6


def samples_of_points(problem: TaskProblem, Z: Array, name: str) -> Array:
    """What the criterion bounds at each row z of Z (m, n): forces f_x (m, 3 K) [N] or the rms torque (m, 1) [N m].

    On the analytic path with the m designs and their trajectories stacked into one call
    (:func:`hiab_sim.dynamics.analytic_batch.batched_inverse_dynamics`); it agrees with the MuJoCo
    path to ~1e-14 relative.
    """
    Z = np.atleast_2d(np.asarray(Z, dtype=float))
    m = Z.shape[0]
    xi = Z[:, : problem.n_xi] * XI_SCALE
    c = problem.c_ref[None] + C_SCALE * Z[:, problem.n_xi :].reshape(m, 3, problem.basis.n)
    q, dq, ddq = (np.einsum("kn,mjn->mkj", B, c) for B in problem.B)
    f, v, a, _ = batched_inverse_dynamics(problem.study.crane, xi, q, dq, ddq, problem.tcp_force)
    if name == "peak_force":
        return f.reshape(m, -1)
    if name == "rms_torque":
        tau = np.stack(
            [drive_state(p, f[..., i], v[..., i], a[..., i]).motor_torque for i, p in enumerate(problem.emlas)],
            axis=-1,
        )
        return np.sqrt(np.mean(np.sum(tau**2, axis=-1), axis=-1))[:, None]
    raise InvalidInputError("--against", name, f"must be one of {', '.join(CRITERIA)}")


def criterion_samples(problem: TaskProblem, z: Array, name: str) -> Array:
    """What the criterion bounds at one z: forces f_x (3 K,) [N] or the rms motor torque (1,) [N m]."""
    return samples_of_points(problem, np.asarray(z, dtype=float)[None], name)[0]


def samples_jacobian(problem: TaskProblem, z: Array, name: str) -> Array:
    """D samples / dz by central differences, all 2 n perturbations in one stacked call, (S, n)."""
    z = np.asarray(z, dtype=float)
    n = len(z)
    step = problem.fd_step * np.maximum(1.0, np.abs(z))
    Z = np.repeat(z[None], 2 * n, axis=0)
    Z[np.arange(n), np.arange(n)] += step
    Z[n + np.arange(n), np.arange(n)] -= step
    s = samples_of_points(problem, Z, name)
    return ((s[:n] - s[n:]) / (2.0 * step[:, None])).T


def criterion(problem: TaskProblem, z: Array, name: str) -> float:
    """The criterion's value at z [N or N m]."""
    return float(np.max(np.abs(criterion_samples(problem, z, name))))


class EpsilonProblem:
    """The study's NLP with criterion <= epsilon appended (rows scaled by ``scale``)."""

    def __init__(self, problem: TaskProblem, name: str, epsilon: float, scale: float) -> None:
        self.problem, self.name, self.epsilon, self.scale = problem, name, float(epsilon), float(scale)

    def rows(self, z: Array) -> Array:
        """Scaled epsilon rows, feasible where >= 0."""
        s = criterion_samples(self.problem, z, self.name)
        if self.name == "peak_force":
            return np.concatenate([self.epsilon - s, self.epsilon + s]) / self.scale
        return (self.epsilon - s) / self.scale

    def rows_jacobian(self, z: Array) -> Array:
        """Jacobian of :meth:`rows` with respect to z, (m, n)."""
        d = samples_jacobian(self.problem, z, self.name) / self.scale
        return np.vstack([-d, d]) if self.name == "peak_force" else -d

    def constraints(self, z: Array) -> Array:
        """The study's inequality rows and the epsilon rows."""
        return np.concatenate([self.problem.constraints(z), self.rows(z)])

    def constraints_jacobian(self, z: Array) -> Array:
        """Their Jacobian."""
        return np.vstack([self.problem.constraints_jacobian(z), self.rows_jacobian(z)])

    def max_violation(self, z: Array) -> float:
        """Largest scaled violation of the study's rows, bounds and the epsilon rows."""
        return max(self.problem.max_violation(z), float(max(0.0, -self.rows(z).min())))

    def solve(self, z0: Array, maxiter: int) -> tuple[Array, bool, str, int]:
        """SLSQP from z0 (need not be feasible): (z, accepted, message, iterations)."""
        p = self.problem
        bounds = [
            (lo if np.isfinite(lo) else None, hi if np.isfinite(hi) else None)
            for lo, hi in zip(p.lower, p.upper, strict=True)
        ]
        try:
            res = minimize(
                p.cost,
                np.asarray(z0, dtype=float),
                jac=p.cost_gradient,
                method="SLSQP",
                bounds=bounds,
                constraints=[
                    {"type": "eq", "fun": p.equalities, "jac": p.equalities_jacobian},
                    {"type": "ineq", "fun": self.constraints, "jac": self.constraints_jacobian},
                ],
                options={"maxiter": maxiter, "ftol": p.study.solver.ftol},
            )
        except InvalidInputError as error:  # a trial point left the model's domain
            return np.asarray(z0, dtype=float), False, f"a trial point left the model's domain: {error}", 0
        z = np.asarray(res.x, dtype=float)
        accepted = bool(res.success) and self.max_violation(z) <= FEASIBLE
        return z, accepted, str(res.message), int(res.nit)


@dataclass(frozen=True)
class FrontPoint:
    """One point of the front: epsilon, the criterion reached, costf2 [W^2 s], the objective, status.

    ``objective_value`` is the study's objective [``objective_unit``: J for battery_energy, W^2 s
    for costf2], ``objective`` the same divided by its value at the study's start.
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

    def as_row(self) -> dict[str, Any]:
        """A table row."""
        row: dict[str, Any] = {
            k: getattr(self, k)
            for k in ("epsilon", "criterion", "costf2_W2s", "objective_value", "objective_unit", "objective")
        }
        row.update({f"xi_{k}": v for k, v in enumerate(self.xi)})
        row.update(accepted=self.accepted, message=self.message, iterations=self.iterations)
        return row


def minimise_criterion(problem: TaskProblem, z0: Array, name: str) -> tuple[Array, float, bool]:
    """The least criterion the study's constraints allow: min t s.t. -t <= s_k(z) <= t (epigraph form).

    Returns (z, c_min, converged); variables (z, t) with t scaled by the criterion at z0.
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

    bounds = [
        (lo if np.isfinite(lo) else None, hi if np.isfinite(hi) else None)
        for lo, hi in zip(p.lower, p.upper, strict=True)
    ]
    x0 = np.append(np.asarray(z0, dtype=float), 1.0)
    res = minimize(
        lambda x: x[n],
        x0,
        jac=lambda x: np.eye(n + 1)[n],
        method="SLSQP",
        bounds=[*bounds, (0.0, None)],
        constraints=[
            {
                "type": "eq",
                "fun": lambda x: p.equalities(x[:n]),
                "jac": lambda x: np.hstack([p.equalities_jacobian(x[:n]), np.zeros((12, 1))]),
            },
            {"type": "ineq", "fun": ineq, "jac": ineq_jacobian},
        ],
        options={"maxiter": p.study.solver.maxiter, "ftol": p.study.solver.ftol},
    )
    z = np.asarray(res.x[:n], dtype=float)
    return z, criterion(p, z, name), bool(res.success) and p.max_violation(z) <= FEASIBLE


def pareto_front(problem: TaskProblem, z_optimum: Array, name: str, points: int) -> list[FrontPoint]:
    """The front from the plain optimum (epsilon = its criterion c_0) to the least criterion c_min.

    Args:
        problem: The study's NLP.
        z_optimum: The plain study's optimum (scaled z), e.g. from :func:`hiab_sim.study.solvers.slsqp.solve`.
        name: ``peak_force`` or ``rms_torque``.
        points: Number of epsilon values (>= 2), equally spaced from c_0 to c_min.

    """
    if points < 2:
        raise InvalidInputError("--points", points, "must be >= 2")
    if name not in CRITERIA:
        raise InvalidInputError("--against", name, f"must be one of {', '.join(CRITERIA)}")
    c0 = criterion(problem, z_optimum, name)
    z_min, c_min, converged = minimise_criterion(problem, z_optimum, name)
    if not converged:
        raise SolverError(f"minimising {name} subject to the study's constraints did not converge")
    front = [_point(problem, z_optimum, name, c0, True, "the plain optimum (epsilon inactive)", 0)]
    z = z_optimum
    for epsilon in np.linspace(c0, c_min, points)[1:]:
        eps_problem = EpsilonProblem(problem, name, float(epsilon), c0)
        z_new, accepted, message, iterations = eps_problem.solve(z, problem.study.solver.maxiter)
        if not accepted:
            z_new, accepted, message, iterations = eps_problem.solve(z_min, problem.study.solver.maxiter)
        front.append(_point(problem, z_new, name, float(epsilon), accepted, message, iterations))
        if accepted:
            z = z_new
    return front


def _point(
    problem: TaskProblem, z: Array, name: str, epsilon: float, accepted: bool, message: str, iterations: int
) -> FrontPoint:
    ev = problem.evaluate(z)
    return FrontPoint(
        epsilon,
        criterion(problem, z, name),
        costf2(problem.emlas, problem.dt).value(ev),
        ev.cost,
        problem.objective.unit,
        ev.cost / problem.cost_scale,
        tuple(float(v) for v in ev.lengths.as_array()),
        accepted,
        message,
        iterations,
    )


def front_figure_png(front: list[FrontPoint], name: str, title: str) -> bytes:
    """PNG of the front: the objective against the criterion, the plain optimum marked.

    The criterion axis also shows the change from the plain optimum in %, so a narrow span
    (a front over a few tenths of a percent) reads as what it is.
    """
    from hiab_sim.figure_io import new_figure, png_bytes

    words = name.replace("_", " ")
    unit = CRITERIA[name]
    k = 1e-3 if unit == "N" else 1.0  # forces in kN
    unit = "kN" if unit == "N" else unit
    ok = [p for p in front if p.accepted]
    fig = new_figure((6.6, 4.8))
    ax = fig.add_subplot()
    ax.plot([k * p.criterion for p in ok], [p.objective for p in ok], "o-", color=colour("optimal"),
            label="least objective for each limit on the criterion")  # fmt: skip
    ax.plot(k * front[0].criterion, front[0].objective, "*", color=colour("initial"), mec="k", ms=14,
            label="plain optimum (no limit on the criterion)")  # fmt: skip
    bad = [p for p in front if not p.accepted]
    if bad:
        ax.plot([k * p.epsilon for p in bad], [p.objective for p in bad], "x", color="red", label="not converged")
    base = k * front[0].criterion
    if base != 0.0:

        def to_percent(c: ArrayLike) -> ArrayLike:
            return 100.0 * (np.asarray(c, dtype=float) / base - 1.0)

        def from_percent(d: ArrayLike) -> ArrayLike:
            return base * (1.0 + np.asarray(d, dtype=float) / 100.0)

        top = ax.secondary_xaxis("top", functions=(to_percent, from_percent))
        top.set_xlabel(f"{words}: change from the plain optimum [%]")
    ax.set_xlabel(f"{words} [{unit}]")
    ax.set_ylabel(f"objective ({front[0].objective_unit}) / its value at the start")
    ax.set_title(f"{title}: what limiting the {words} costs", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return png_bytes(fig)

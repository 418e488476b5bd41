"""One design for a mix of tasks: shared link lengths Xi, each task its own trajectory and constraints.

The NLP of a study with tasks k = 1..T (:mod:`hiab_sim.study.spec.tasks`) is

    min_z  sum_k w_k f_k(Xi, c_k) / f_scale
    s.t.   g_k(Xi, c_k) >= 0,  e_k(c_k) = 0,  Xi in [xi_low, xi_up]     for every task k,

with z = [z_xi (6), z_c1, z_c2, ...] (each z_ck the scaled B-spline coefficients of task k around
its own inverse-kinematics fit), f_k the task's objective (eq. ``costf2`` by default, [W^2 s]) on
its own collocation grid, w_k its weight and f_scale = sum_k w_k f_k at the study's start. Each
task is one :class:`~hiab_sim.study.nlp.problem.LinkLengthProblem` (its grid, spline, reference,
payload and every constraint block); this class only stacks them. Rows and equalities are the
tasks' in task order, named ``<task>: <row>``; the Jacobians are block-sparse in the coefficients
(task k's rows depend on Xi and c_k only) and are assembled dense for SLSQP. Rows that depend on
Xi alone and are the same for every task (the working range of ``bounds.working_range: crane``)
are kept once, with the first task: duplicated rows are linearly dependent and would make the
QP subproblem degenerate.

:class:`MixProblem` has the public surface :mod:`hiab_sim.study.solvers.slsqp` uses of a
LinkLengthProblem (cost, constraints, equalities and their Jacobians, margins, max_violation,
initial_point, unpack, evaluate, bounds, names), so the same driver solves either.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.crane.description import LinkLengths
from hiab_sim.emla import EmlaSet
from hiab_sim.study.nlp.blocks import WorkingRange
from hiab_sim.study.nlp.interface import N_XI, Array
from hiab_sim.study.nlp.problem import Evaluation, LinkLengthProblem
from hiab_sim.study.spec.study_file import Study


@dataclass(frozen=True)
class MixEvaluation:
    """The mix at one point: weighted cost [W^2 s], stacked rows, and each task's evaluation."""

    z: Array
    lengths: LinkLengths
    cost: float  # sum_k w_k f_k [W^2 s, weighted]
    constraints: Array
    equalities: Array
    tasks: tuple[Evaluation, ...]


class MixProblem:
    """The scaled NLP of a study with several tasks (module docstring).

    Args:
        study: The study (``study.tasks`` has one or more tasks).
        emlas: EMLA set (default: the study's own).
        id_path: ``mujoco`` or ``analytic`` (default: the study's).
        tightened: As :class:`LinkLengthProblem` (False: nominal bands for re-checks).
        objective: Name of every task's objective.
        fine: Evaluate every task on its fine grid (reports), not its collocation grid.

    """

    def __init__(
        self,
        study: Study,
        emlas: EmlaSet | None = None,
        id_path: str | None = None,
        tightened: bool = True,
        objective: str | None = None,
        fine: bool = False,
    ) -> None:
        self.study = study
        self.tasks = study.tasks
        problems = []
        for task in study.tasks:
            base = LinkLengthProblem(study, emlas, id_path, tightened=tightened, objective=objective, task=task)
            if fine:
                base = LinkLengthProblem(
                    study,
                    base.emlas,
                    base.id_path,
                    times=base.fine_times(),
                    cost_scale=base.cost_scale,
                    tightened=tightened,
                    objective=objective,
                    task=task,
                )
            problems.append(base)
        self.problems: tuple[LinkLengthProblem, ...] = tuple(problems)
        first = self.problems[0]
        self.objective = first.objective  # every task's (the study's); the mix weighs their values
        self.emlas = first.emlas
        self.id_path = first.id_path
        self.crane = first.crane
        self.envelope_margin = first.envelope_margin  # the study's, the same for every task
        self.weights = np.array([task.weight for task in study.tasks])
        # the working range the starts must serve: the widest of the tasks' (the crane's for ``crane``)
        self.working = tuple(
            (min(p.working[j][0] for p in self.problems), max(p.working[j][1] for p in self.problems))
            for j in range(len(first.working))
        )
        self.n_xi = N_XI
        self.offsets: list[int] = []
        n = N_XI
        for p in self.problems:
            self.offsets.append(n)
            n += p.n_c
        self.n = n
        self.lower = np.concatenate([first.lower[:N_XI], np.full(n - N_XI, -np.inf)])
        self.upper = np.concatenate([first.upper[:N_XI], np.full(n - N_XI, np.inf)])
        self.rows: list[NDArray[np.intp]] = [self._kept_rows(k) for k in range(len(self.problems))]
        self.constraint_names = [
            f"{task.name}: {p.constraint_names[i]}"
            for task, p, rows in zip(self.tasks, self.problems, self.rows, strict=True)
            for i in rows
        ]
        self.clearance = np.concatenate([p.clearance[rows] for p, rows in zip(self.problems, self.rows, strict=True)])
        self.equality_names = [f"{task.name}: rest {i}" for task in self.tasks for i in range(12)]
        self.cost_scale = 1.0
        self.cost_scale = max(self.evaluate(self.initial_point(study.initial_lengths)).cost, 1e-300)

    def _kept_rows(self, k: int) -> NDArray[np.intp]:
        """Row indices of task k's rows in the mix: all, less the Xi-only rows task 0 already has."""
        p = self.problems[k]
        keep = np.ones(len(p.constraint_names), dtype=bool)
        if k > 0:
            for block in p.layout.blocks:
                if isinstance(block, WorkingRange):
                    twin = next(b for b in self.problems[0].layout.blocks if isinstance(b, WorkingRange))
                    if np.array_equal(block.theta, twin.theta) and block.clearance() == twin.clearance():
                        keep[p.layout.slices[block.name]] = False
        return np.flatnonzero(keep)

    # -- variables ---------------------------------------------------------------------------

    def task_z(self, z: Array, k: int) -> Array:
        """Task k's own z = [z_xi, z_ck] from the mix's z."""
        z = np.asarray(z, dtype=float)
        off = self.offsets[k]
        return np.concatenate([z[:N_XI], z[off : off + self.problems[k].n_c]])

    def initial_point(self, lengths: LinkLengths, coefficients: list[Array] | None = None) -> Array:
        """Scaled z for link lengths and each task's coefficients (default: their inverse-kinematics fits)."""
        parts = [self.problems[0].initial_point(lengths)[:N_XI]]
        for k, p in enumerate(self.problems):
            c = None if coefficients is None else coefficients[k]
            parts.append(p.initial_point(lengths, c)[N_XI:])
        return np.concatenate(parts)

    def unpack(self, z: Array) -> tuple[LinkLengths, list[Array]]:
        """(Xi, [c_k (3, N_k)]) from scaled z."""
        lengths = self.problems[0].unpack(self.task_z(z, 0))[0]
        return lengths, [p.unpack(self.task_z(z, k))[1] for k, p in enumerate(self.problems)]

    # -- evaluation --------------------------------------------------------------------------

    @property
    def n_evaluations(self) -> int:
        """ID evaluations over every task."""
        return sum(p.n_evaluations for p in self.problems)

    @property
    def n_gradients(self) -> int:
        """Gradient evaluations over every task."""
        return sum(p.n_gradients for p in self.problems)

    def evaluate(self, z: Array) -> MixEvaluation:
        """Every task at z (each task problem caches its own evaluations)."""
        z = np.array(z, dtype=float)
        evs = tuple(p.evaluate(self.task_z(z, k)) for k, p in enumerate(self.problems))
        return MixEvaluation(
            z=z,
            lengths=evs[0].lengths,
            cost=float(sum(w * ev.cost for w, ev in zip(self.weights, evs, strict=True))),
            constraints=np.concatenate([ev.constraints[rows] for ev, rows in zip(evs, self.rows, strict=True)]),
            equalities=np.concatenate([ev.equalities for ev in evs]),
            tasks=evs,
        )

    def cost(self, z: Array) -> float:
        """Scaled cost sum_k w_k f_k / f_scale."""
        return self.evaluate(z).cost / self.cost_scale

    def constraints(self, z: Array) -> Array:
        """Scaled inequality rows of every task, g(z) >= 0."""
        return self.evaluate(z).constraints

    def equalities(self, z: Array) -> Array:
        """Every task's rest-to-rest equalities."""
        return self.evaluate(z).equalities

    def margins(self, z: Array) -> Array:
        """Nominal scaled margins (the rows without the optimiser's clearance)."""
        return self.evaluate(z).constraints + self.clearance

    def max_violation(self, z: Array) -> float:
        """Largest violation over every task (its rows, equalities and the Xi bounds), scaled units."""
        return max(p.max_violation(self.task_z(z, k)) for k, p in enumerate(self.problems))

    # -- gradients ---------------------------------------------------------------------------

    def cost_gradient(self, z: Array) -> Array:
        """d(scaled cost)/dz: sum_k w_k (df_k/dz) / f_scale."""
        grad = np.zeros(self.n)
        for k, p in enumerate(self.problems):
            g = p.cost_gradient(self.task_z(z, k)) * (self.weights[k] * p.cost_scale / self.cost_scale)
            grad[:N_XI] += g[:N_XI]
            grad[self.offsets[k] : self.offsets[k] + p.n_c] = g[N_XI:]
        return grad

    def constraints_jacobian(self, z: Array) -> Array:
        """D g / dz (m, n): task k's rows in the Xi columns and its own coefficient columns."""
        return self._stack([p.constraints_jacobian(self.task_z(z, k))[rows] for k, (p, rows) in self._pairs()])

    def equalities_jacobian(self, z: Array) -> Array:
        """D e / dz (constant), (12 T, n)."""
        return self._stack([p.equalities_jacobian(self.task_z(z, k)) for k, (p, _) in self._pairs()])

    def _pairs(self) -> list[tuple[int, tuple[LinkLengthProblem, NDArray[np.intp]]]]:
        return list(enumerate(zip(self.problems, self.rows, strict=True)))

    def _stack(self, parts: list[Array]) -> Array:
        out = np.zeros((sum(len(p) for p in parts), self.n))
        r = 0
        for k, part in enumerate(parts):
            off, n_c = self.offsets[k], self.problems[k].n_c
            out[r : r + len(part), :N_XI] = part[:, :N_XI]
            out[r : r + len(part), off : off + n_c] = part[:, N_XI:]
            r += len(part)
        return out


def make_problem(study: Study, id_path: str | None = None) -> LinkLengthProblem | MixProblem:
    """The study's NLP: a :class:`LinkLengthProblem` for one task (today's path), else a :class:`MixProblem`."""
    if len(study.tasks) == 1:
        return LinkLengthProblem(study, id_path=id_path)
    return MixProblem(study, id_path=id_path)


#: Either NLP; :mod:`hiab_sim.study.solvers.slsqp` drives both.
Problem = LinkLengthProblem | MixProblem

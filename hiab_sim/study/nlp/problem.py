"""The study's NLP: shared link lengths Xi, each task its own trajectory and constraints (one task or many).

The NLP of a study with tasks k = 1..T (:mod:`hiab_sim.study.spec.tasks`; a single-reference
study is one task of weight 1) is

    min_z  sum_k w_k f_k(Xi, c_k) / f_scale
    s.t.   g_k(Xi, c_k) >= 0,  e_k(c_k) = 0,  Xi in [xi_low, xi_up]     for every task k,

with z = [z_xi (6), z_c1, z_c2, ...] (each z_ck the scaled B-spline coefficients of task k around
its own inverse-kinematics fit), f_k the study's objective (:data:`hiab_sim.study.nlp.objectives.OBJECTIVES`,
eq. ``costf2`` by default [W^2 s]) on the task's own collocation grid, w_k its weight and
f_scale = sum_k w_k f_k at the study's start. Each task's rows and cost are one
:class:`~hiab_sim.study.nlp.task_problem.TaskProblem` (its grid, spline, reference, payload and
constraint blocks); this class stacks them. For one task of weight 1 every value and derivative is
the task's own, bit for bit (w f / (w f_start) with w = 1).

Rows and equalities are the tasks' in task order, named ``<task>: <row>`` when there are several
tasks (a single task's rows keep their own names). A block of Xi only is the same rows in every
task when its :meth:`~hiab_sim.study.nlp.interface.ConstraintBlock.shared_key` agrees (the working range
and the buildable range of ``bounds.working_range: crane``, the mounting space): it is held once,
with the first task that has it, since repeated rows are linearly dependent and make the QP
subproblem degenerate. :attr:`StudyProblem.blocks` lists every held block with its rows in the
stacked problem (what the sensitivities read). The Jacobians are block-sparse in the coefficients
(task k's rows depend on Xi and c_k only) and are assembled dense for SLSQP.
"""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaSet
from hiab_sim.study.constraints.block_registry import BlockFactory
from hiab_sim.study.machines.protocol import Design
from hiab_sim.study.nlp.interface import ConstraintBlock, ScaledProblem
from hiab_sim.study.nlp.task_problem import Evaluation, TaskProblem
from hiab_sim.study.spec.study_file import Study


@dataclass(frozen=True)
class StudyEvaluation:
    """The study at one point: weighted objective [its unit], stacked rows, and each task's evaluation."""

    z: Array
    lengths: Design
    cost: float  # sum_k w_k f_k [the objective's unit, weighted]
    constraints: Array
    equalities: Array
    tasks: tuple[Evaluation, ...]


@dataclass(frozen=True)
class StackedBlock:
    """One held constraint block: its task, the block, and its rows in the task and in the stacked problem."""

    task: int
    block: ConstraintBlock
    local: slice  # rows in the task's own row vector
    rows: slice  # rows in the stacked problem


class StudyProblem(ScaledProblem):
    """The scaled NLP of a study of one or more tasks (module docstring).

    Args:
        study: The study.
        emlas: EMLA set (default: the study's own).
        id_path: ``mujoco`` or ``analytic`` (default: the study's).
        tightened: As :class:`TaskProblem` (False: nominal bands for re-checks).
        objective: Name of the objective (default: the study's).
        fine: Evaluate every task on its fine grid (reports), not its collocation grid.
        cost_scales: Each task's cost scale (default: its objective at the study's start); pass a
            problem's own to evaluate the same scaling on another grid.
        extra_blocks: Each task's blocks of this problem only, after the registered ones
            (:class:`~hiab_sim.study.nlp.task_problem.TaskProblem`; a Pareto point's epsilon rows).

    """

    def __init__(
        self,
        study: Study,
        emlas: EmlaSet | None = None,
        id_path: str | None = None,
        tightened: bool = True,
        objective: str | None = None,
        fine: bool = False,
        cost_scales: list[float] | None = None,
        extra_blocks: BlockFactory | None = None,
    ) -> None:
        self.study = study
        self.tasks = study.tasks
        problems = []
        for k, task in enumerate(study.tasks):
            scale = None if cost_scales is None else cost_scales[k]
            base = TaskProblem(
                study,
                emlas,
                id_path,
                cost_scale=scale,
                tightened=tightened,
                objective=objective,
                task=task,
                extra_blocks=extra_blocks,
            )
            if fine:
                base = TaskProblem(
                    study,
                    base.emlas,
                    base.id_path,
                    times=base.fine_times(),
                    cost_scale=base.cost_scale,
                    tightened=tightened,
                    objective=objective,
                    task=task,
                    extra_blocks=extra_blocks,
                )
            problems.append(base)
        self.problems: tuple[TaskProblem, ...] = tuple(problems)
        first = self.problems[0]
        self.objective = first.objective  # every task's (the study's); the study weighs their values
        self.emlas = first.emlas
        self.id_path = first.id_path
        self.model = first.model
        self.tightened = tightened
        self.envelope_margin = first.envelope_margin  # the study's, the same for every task
        self.weights = np.array([task.weight for task in study.tasks])
        # the working range the starts must serve: the widest of the tasks' (the crane's for ``crane``)
        self.working = tuple(
            (min(p.working[j][0] for p in self.problems), max(p.working[j][1] for p in self.problems))
            for j in range(len(first.working))
        )
        self.n_xi = n_xi = first.n_xi
        self.offsets: list[int] = []
        n = n_xi
        for p in self.problems:
            self.offsets.append(n)
            n += p.n_c
        self.n = n
        self.lower = np.concatenate([first.lower[:n_xi], np.full(n - n_xi, -np.inf)])
        self.upper = np.concatenate([first.upper[:n_xi], np.full(n - n_xi, np.inf)])
        self.blocks: tuple[StackedBlock, ...] = self._stack_blocks()
        self.rows: list[NDArray[np.intp]] = [
            np.concatenate(
                [np.arange(b.local.start, b.local.stop) for b in self.blocks if b.task == k] or [np.zeros(0)]
            ).astype(np.intp)
            for k in range(len(self.problems))
        ]
        self.constraint_names = [
            self.row_name(k, p.constraint_names[i])
            for k, (p, rows) in enumerate(zip(self.problems, self.rows, strict=True))
            for i in rows
        ]
        self.clearance = np.concatenate([p.clearance[rows] for p, rows in zip(self.problems, self.rows, strict=True)])
        self.equality_names = [
            self.row_name(k, f"rest {i}") for k in range(len(self.tasks)) for i in range(first.n_equalities)
        ]
        self.cost_scale = 1.0
        self.cost_scale = max(
            abs(self.evaluate(self.initial_point(study.initial_lengths)).cost), 1e-300
        )  # |f0|: an energy may be negative

    @property
    def n_tasks(self) -> int:
        """Number of tasks."""
        return len(self.problems)

    def row_name(self, k: int, row: str) -> str:
        """Task k's row as the stacked problem names it (``<task>: <row>`` with several tasks)."""
        return row if self.n_tasks == 1 else f"{self.tasks[k].name}: {row}"

    def _stack_blocks(self) -> tuple[StackedBlock, ...]:
        """Every task's blocks in task order, a block of Xi only held once per shared key."""
        seen: set[Hashable] = set()
        out: list[StackedBlock] = []
        r = 0
        for k, p in enumerate(self.problems):
            for block in p.layout.blocks:
                key = block.shared_key()
                if key is not None:
                    if key in seen:
                        continue
                    seen.add(key)
                local = p.layout.slices[block.name]
                count = local.stop - local.start
                out.append(StackedBlock(k, block, local, slice(r, r + count)))
                r += count
        return tuple(out)

    # -- variables ---------------------------------------------------------------------------

    def task_z(self, z: Array, k: int) -> Array:
        """Task k's own z = [z_xi, z_ck] from the study's z."""
        z = np.asarray(z, dtype=float)
        off = self.offsets[k]
        return np.concatenate([z[: self.n_xi], z[off : off + self.problems[k].n_c]])

    def initial_point(self, lengths: Design, coefficients: list[Array] | None = None) -> Array:
        """Scaled z for link lengths and each task's coefficients (default: their inverse-kinematics fits)."""
        parts = [self.problems[0].initial_point(lengths)[: self.n_xi]]
        for k, p in enumerate(self.problems):
            c = None if coefficients is None else coefficients[k]
            parts.append(p.initial_point(lengths, c)[self.n_xi :])
        return np.concatenate(parts)

    def unpack(self, z: Array) -> tuple[Design, list[Array]]:
        """(Xi, [c_k (n, N_k)]) from scaled z."""
        lengths = self.problems[0].unpack(self.task_z(z, 0))[0]
        return lengths, [p.unpack(self.task_z(z, k))[1] for k, p in enumerate(self.problems)]

    def with_lengths(self, z: Array, lengths: Design) -> Array:
        """Z with its Xi replaced by ``lengths`` (every trajectory kept)."""
        out = np.array(z, dtype=float)
        out[: self.n_xi] = self.problems[0].initial_point(lengths)[: self.n_xi]
        return out

    # -- evaluation --------------------------------------------------------------------------

    @property
    def n_evaluations(self) -> int:
        """ID evaluations over every task."""
        return sum(p.n_evaluations for p in self.problems)

    @property
    def n_gradients(self) -> int:
        """Gradient evaluations over every task."""
        return sum(p.n_gradients for p in self.problems)

    def evaluate(self, z: Array) -> StudyEvaluation:
        """Every task at z (each task problem caches its own evaluations)."""
        z = np.array(z, dtype=float)
        evs = tuple(p.evaluate(self.task_z(z, k)) for k, p in enumerate(self.problems))
        return StudyEvaluation(
            z=z,
            lengths=evs[0].lengths,
            cost=float(sum(w * ev.cost for w, ev in zip(self.weights, evs, strict=True))),
            constraints=np.concatenate([ev.constraints[rows] for ev, rows in zip(evs, self.rows, strict=True)]),
            equalities=np.concatenate([ev.equalities for ev in evs]),
            tasks=evs,
        )

    def max_violation(self, z: Array) -> float:
        """Largest violation over every task (its rows, equalities and the Xi bounds), scaled units."""
        return max(p.max_violation(self.task_z(z, k)) for k, p in enumerate(self.problems))

    # -- gradients ---------------------------------------------------------------------------

    def cost_gradient(self, z: Array) -> Array:
        """d(scaled cost)/dz: sum_k w_k (df_k/dz) / f_scale."""
        grad = np.zeros(self.n)
        for k, p in enumerate(self.problems):
            g = p.cost_gradient(self.task_z(z, k)) * (self.weights[k] * p.cost_scale / self.cost_scale)
            grad[: self.n_xi] += g[: self.n_xi]
            grad[self.offsets[k] : self.offsets[k] + p.n_c] = g[self.n_xi :]
        return grad

    def constraints_jacobian(self, z: Array) -> Array:
        """D g / dz (m, n): task k's rows in the Xi columns and its own coefficient columns."""
        return self._stack([p.constraints_jacobian(self.task_z(z, k))[rows] for k, (p, rows) in self._pairs()])

    def equalities_jacobian(self, z: Array) -> Array:
        """D e / dz (constant), (4 n T, n)."""
        return self._stack([p.equalities_jacobian(self.task_z(z, k)) for k, (p, _) in self._pairs()])

    def _pairs(self) -> list[tuple[int, tuple[TaskProblem, NDArray[np.intp]]]]:
        return list(enumerate(zip(self.problems, self.rows, strict=True)))

    def _stack(self, parts: list[Array]) -> Array:
        out = np.zeros((sum(len(p) for p in parts), self.n))
        r = 0
        for k, part in enumerate(parts):
            off, n_c = self.offsets[k], self.problems[k].n_c
            out[r : r + len(part), : self.n_xi] = part[:, : self.n_xi]
            out[r : r + len(part), off : off + n_c] = part[:, self.n_xi :]
            r += len(part)
        return out


def make_problem(study: Study, id_path: str | None = None) -> StudyProblem:
    """The study's NLP (one type for one task or many)."""
    return StudyProblem(study, id_path=id_path)


#: The NLP every solver, report and analysis takes.
Problem = StudyProblem

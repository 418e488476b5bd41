"""The NLP in the form IPOPT holds it: the sparse Jacobian's pattern and values, range pairs as two-sided rows.

The NLP's Jacobian is sparse by structure: a per-sample row
(:class:`~hiab_sim.study.nlp.interface.PerSampleBlock`) depends on Xi and on the k + 1 B-spline
coefficients per joint whose support covers its sample, another row (an integral, the working
range) on Xi and its task's coefficients; rows of another task never depend on a task's
coefficients. :func:`task_sparsity` builds that pattern from the blocks; the values are the
problem's exact-structure Jacobian at the pattern.

One change of form: a pair of rows that bound one quantity from both sides
(:attr:`~hiab_sim.study.nlp.interface.PerSampleBlock.pairs`: tracking bands, joint and joint-velocity
limits, 0 <= x <= stroke), whose values add up to a constant, is held as one two-sided row
0 <= g_a <= g_a + g_b (:func:`task_rows`): 17 of the 45 rows per sample, the same feasible set and a
KKT system ~40 % smaller. The Jacobian's values are gathered task by task into the pattern's
column-major order (:class:`SparseJacobian`) for :func:`hiab_sim.study.solvers.ipopt.solve_ipopt`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import sparse

from hiab_sim.arrays import Array
from hiab_sim.study.nlp.interface import PerSampleBlock
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import TaskProblem


def task_sparsity(problem: TaskProblem) -> sparse.csr_matrix:
    """Structural nonzeros of one task's constraint Jacobian (rows, n_xi + J N) as a 0/1 matrix.

    n_xi design variables (6 on the XS 031, the machine file's count otherwise) and J joints' N
    coefficients each.
    """
    support = np.any(problem.B != 0.0, axis=0)  # (K, N): basis functions nonzero at each sample
    n_c, n_xi, n_joints = problem.basis.n, problem.n_xi, problem.n_joints
    rows: list[Array] = []
    for block in problem.layout.blocks:
        s = problem.layout.slices[block.name]
        count = s.stop - s.start
        if isinstance(block, PerSampleBlock):
            per = count // len(block.times)
            # the block's samples are the problem's samples (same grid)
            cols = np.concatenate([np.ones((len(block.times), n_xi), bool), np.tile(support, (1, n_joints))], axis=1)
            rows.append(np.repeat(cols, per, axis=0))
        else:
            rows.append(np.ones((count, n_xi + n_joints * n_c), bool))
    return sparse.csr_matrix(np.vstack(rows)).astype(float)  # the 0/1 values after the pattern: no dense float copy


def range_pairs(problem: TaskProblem) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Task rows (a, b) whose values add up to a constant (:attr:`PerSampleBlock.pairs`), as two index arrays."""
    first: list[Array] = []
    second: list[Array] = []
    for block in problem.layout.blocks:
        if isinstance(block, PerSampleBlock) and block.pairs:
            starts = problem.layout.slices[block.name].start + len(block.sample_rows) * np.arange(len(block.times))
            for a, b in block.pairs:
                first.append(starts + a)
                second.append(starts + b)
    if not first:
        return np.zeros(0, np.intp), np.zeros(0, np.intp)
    return np.concatenate(first).astype(np.intp), np.concatenate(second).astype(np.intp)


@dataclass(frozen=True)
class TaskRows:
    """The rows IPOPT holds for one task: task-local row indices, each with its pair's row or -1."""

    problem: TaskProblem
    rows: NDArray[np.intp]  # task-local rows, in order
    partner: NDArray[np.intp]  # task-local row of each held row's pair (its upper limit), -1 if none
    offset: int  # first coefficient column of the task in z


def task_rows(problem: StudyProblem) -> list[TaskRows]:
    """Each task's rows as IPOPT holds them: every kept row, a range pair as one two-sided row.

    A pair's second row b is dropped and its first row a bounded 0 <= g_a <= g_a + g_b: the same
    feasible set with half the rows (the interior point's KKT system shrinks with them).
    """
    parts = list(zip(problem.problems, problem.rows, problem.offsets, strict=True))
    out = []
    for p, kept, offset in parts:
        first, second = range_pairs(p)
        partner = np.full(len(p.constraint_names), -1, dtype=np.intp)
        both = np.isin(first, kept) & np.isin(second, kept)
        partner[first[both]] = second[both]
        held = kept[~np.isin(kept, second[both])]
        out.append(TaskRows(p, held, partner[held], offset))
    return out


def task_z(problem: StudyProblem, z: Array, k: int) -> Array:
    """Task k's own z (the study's z cut to Xi and the task's coefficients)."""
    return problem.task_z(z, k)


class SparseJacobian:
    """D[e; g]/dz of the rows IPOPT holds (:func:`task_rows`) as the nonzeros of a fixed CSC pattern.

    The pattern is the equalities' nonzeros (constant, 4 J rows per task) over each task's held rows
    of :func:`task_sparsity`. :meth:`values` takes each task's own Jacobian (rows, n_xi + J N_k) at
    its pattern (precomputed flat indices) straight into its column-major positions: no dense (m, n)
    matrix of the mix is formed. The last point's values are kept in one buffer, overwritten at the
    next point (IPOPT asks for the Jacobian of the equalities and of the inequalities at the same
    point and copies it).
    """

    def __init__(self, problem: StudyProblem, z0: Array) -> None:
        self.problem = problem
        self.tasks = task_rows(problem)
        self.m_eq = len(problem.equalities(z0))
        eq = sparse.coo_matrix(problem.equalities_jacobian(z0))  # constant: rest-to-rest rows, linear in c
        self.eq_values = eq.data.copy()
        rows, cols = [eq.row], [eq.col]
        self.local: list[tuple[NDArray[np.intp], NDArray[np.intp]]] = []
        first_row = self.m_eq
        for t in self.tasks:
            local = task_sparsity(t.problem)[t.rows].tocoo()
            self.local.append((t.rows[local.row], local.col))
            rows.append(local.row + first_row)
            n_xi = t.problem.n_xi
            cols.append(np.where(local.col < n_xi, local.col, local.col - n_xi + t.offset))
            first_row += len(t.rows)
        self.shape = (first_row, problem.n)
        source = np.arange(1, sum(len(r) for r in rows) + 1, dtype=float)  # 1-based: a 0 would be dropped
        pattern = sparse.csc_matrix((source, (np.concatenate(rows), np.concatenate(cols))), shape=self.shape)
        pattern.sort_indices()
        self.indptr, self.indices = pattern.indptr, pattern.indices
        order = pattern.data.astype(np.intp) - 1  # CSC position -> index into the pieces' concatenation
        # each piece's CSC positions, and each task's entries as flat indices into its (rows, columns) Jacobian
        position = np.empty_like(order)
        position[order] = np.arange(len(order))
        ends = np.cumsum([len(self.eq_values)] + [len(r) for r, _ in self.local])
        self._task_positions = [position[a:b] for a, b in itertools.pairwise(ends)]
        self._task_flat = [
            r * (t.problem.n_xi + t.problem.n_joints * t.problem.basis.n) + c
            for t, (r, c) in zip(self.tasks, self.local, strict=True)
        ]
        self._z: Array | None = None
        self._values = np.zeros(len(order))
        self._values[position[: ends[0]]] = self.eq_values  # constant

    def rows(self, z: Array) -> Array:
        """[e; g] at z: the equalities, then each task's held rows."""
        parts = [self.problem.equalities(z)]
        parts += [t.problem.constraints(task_z(self.problem, z, k))[t.rows] for k, t in enumerate(self.tasks)]
        return np.concatenate(parts)

    def upper(self, z0: Array) -> Array:
        """Upper bounds of [e; g]: 0 for the equalities, g_a + g_b for a range pair's row, else inf."""
        parts = [np.zeros(self.m_eq)]
        for k, t in enumerate(self.tasks):
            g = t.problem.constraints(task_z(self.problem, z0, k))
            parts.append(np.where(t.partner >= 0, g[t.rows] + g[np.maximum(t.partner, 0)], np.inf))
        return np.concatenate(parts)

    def values(self, z: Array) -> Array:
        """The Jacobian's values at z in the pattern's column-major order."""
        if self._z is None or not np.array_equal(z, self._z):
            for k, (t, flat) in enumerate(zip(self.tasks, self._task_flat, strict=True)):
                jacobian = t.problem.constraints_jacobian(task_z(self.problem, z, k))
                self._values[self._task_positions[k]] = jacobian.reshape(-1).take(flat)
            self._z = np.array(z, dtype=float)
        return self._values

    def dense(self, z: Array) -> Array:
        """The Jacobian as a dense (m, n) array (tests)."""
        return sparse.csc_matrix((self.values(z), self.indices, self.indptr), shape=self.shape).toarray()

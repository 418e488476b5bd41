"""The Pareto front's epsilon rows as constraint blocks: the study's NLP with criterion <= epsilon, solved as its own.

A front point (:mod:`hiab_sim.sweep.pareto`) minimises the study's objective subject to every row of
every task and criterion <= epsilon, the criterion the worst over the tasks; so every task gets the
rows below, one more :class:`~hiab_sim.study.nlp.interface.ConstraintBlock` after its own
(:func:`epsilon_problem`). Being blocks, their values read the task's own evaluation (its inverse
dynamics, no second ID), their Jacobian its ID partials chained by the problem through the
B-spline matrices, and the sparse solver derives their pattern from them: each point is solved by
the study's own method (dense SLSQP or IPOPT with sparse Jacobians), whatever the criterion.

* ``peak_force``: per sample k and actuator i, (epsilon - f_x,ik) / s >= 0 and (epsilon + f_x,ik) / s >= 0
  (:class:`PeakForceBound`; the pair adds up to 2 epsilon / s, so IPOPT holds it as one two-sided row);
* ``rms_torque``: (epsilon - sqrt(mean_k sum_i tau_m,ik^2)) / s >= 0 (:class:`RmsTorqueBound`; one row
  over every sample, the motor torques of eq. ``torque_torque`` from :func:`hiab_sim.emla.drive.drive_state`).

s [N or N m] scales the rows to O(1) (the plain optimum's criterion).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaSet
from hiab_sim.emla.drive import drive_state
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.constraints.blocks import opposite_rows
from hiab_sim.study.nlp.interface import (
    ConstraintBlock,
    DenseRows,
    PerSampleBlock,
    Relaxation,
    SamplePartials,
    SampleRows,
    SampleState,
)
from hiab_sim.study.nlp.problem import StudyProblem


def _check_scale(field: str, scale: float, unit: str) -> None:
    if not scale > 0.0:
        raise InvalidInputError(field, scale, "must be > 0", unit)


class PeakForceBound(PerSampleBlock):
    """|f_x| <= epsilon for every actuator at every sample: (epsilon -+ f_x) / scale >= 0.

    Args:
        times: sample times [s], (K,).
        actuators: the actuators' names, in the ID's column order.
        epsilon: the bound [N].
        scale: divisor that makes the rows O(1) [N], > 0.

    """

    def __init__(self, times: Array, actuators: tuple[str, ...], epsilon: float, scale: float) -> None:
        _check_scale("epsilon.peak_force.scale", scale, "N")
        self.name = "epsilon.peak_force"
        self.times = times
        self.epsilon, self.scale = float(epsilon), float(scale)
        self.sample_rows = (*(f"{a}.f_x <= epsilon" for a in actuators), *(f"{a}.f_x >= -epsilon" for a in actuators))
        self.pairs = opposite_rows(len(actuators))  # (epsilon - f) + (epsilon + f) = 2 epsilon

    def values(self, state: SampleState) -> Array:
        """(epsilon - f_x) / scale then (epsilon + f_x) / scale per sample, (K * 2 A,)."""
        f = state.actuators.force
        return (np.concatenate([self.epsilon - f, self.epsilon + f], axis=1) / self.scale).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """-+ df_x/dq9 and -+ df_x/dXi over scale: the ID partials' force outputs (the first A)."""
        A = state.actuators.force.shape[1]
        dq, dxi = partials.id_q[:, :A], partials.id_xi[:, :A]
        return SampleRows(
            np.concatenate([-dq, dq], axis=1) / self.scale, np.concatenate([-dxi, dxi], axis=1) / self.scale
        )

    def relaxation(self, values: Array) -> Relaxation:
        """Per N of epsilon: 1 / scale."""
        return Relaxation.uniform("N", 1.0 / self.scale, len(values))


class RmsTorqueBound(ConstraintBlock):
    """sqrt(mean_k sum_i tau_m,ik^2) <= epsilon: (epsilon - rms) / scale >= 0, one row over every sample.

    Args:
        emlas: the task's EMLAs (their motor torque from the load side's f_x, v_x, a_x).
        epsilon: the bound [N m].
        scale: divisor that makes the row O(1) [N m], > 0.

    """

    def __init__(self, emlas: EmlaSet, epsilon: float, scale: float) -> None:
        _check_scale("epsilon.rms_torque.scale", scale, "N m")
        self.name = "epsilon.rms_torque"
        self.emlas = emlas
        self.epsilon, self.scale = float(epsilon), float(scale)

    def row_names(self) -> list[str]:
        """``epsilon.rms_torque <= <epsilon> N m``."""
        return [f"{self.name} <= {self.epsilon:.6g} N m"]

    def _drives(self, state: SampleState) -> list[Any]:
        act = state.actuators
        return [
            drive_state(e, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
            for i, e in enumerate(self.emlas)
        ]

    @staticmethod
    def _rms(drives: list[Any]) -> tuple[Array, float]:
        tau = np.column_stack([d.motor_torque for d in drives])  # (K, A) [N m]
        return tau, float(np.sqrt(np.mean(np.sum(tau**2, axis=1))))

    def values(self, state: SampleState) -> Array:
        """(epsilon - rms) / scale, (1,)."""
        return np.array([(self.epsilon - self._rms(self._drives(state))[1]) / self.scale])

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """-d rms / (dq9, dXi) / scale: d rms / d tau_ik = tau_ik / (K rms), tau_ik of (f, v, a) of actuator i at k."""
        drives = self._drives(state)
        tau, rms = self._rms(drives)
        K, A = tau.shape
        w = tau / (K * max(rms, 1e-300))
        g = np.zeros((K, 3 * A))  # d rms / d(f_0..f_A-1, v_.., a_..) per sample, the ID's output order
        for i, d in enumerate(drives):
            df, dv, da = d.d_motor_torque
            g[:, i], g[:, A + i], g[:, 2 * A + i] = w[:, i] * df, w[:, i] * dv, w[:, i] * da
        dq = np.einsum("ky,kyq->kq", g, partials.id_q)
        dxi = np.einsum("ky,kyx->x", g, partials.id_xi)
        return DenseRows(dq=-dq[None] / self.scale, dxi=-dxi[None] / self.scale)

    def relaxation(self, values: Array) -> Relaxation:
        """Per N m of epsilon: 1 / scale."""
        return Relaxation.uniform("N m", 1.0 / self.scale, len(values))


def epsilon_block(task: Any, name: str, epsilon: float, scale: float) -> ConstraintBlock:
    """The epsilon rows of criterion ``name`` for one task (a :class:`~hiab_sim.study.nlp.task_problem.TaskProblem`)."""
    if name == "peak_force":
        return PeakForceBound(task.times, tuple(task.emlas.names), epsilon, scale)
    if name == "rms_torque":
        return RmsTorqueBound(task.emlas, epsilon, scale)
    raise InvalidInputError("--against", name, "must be one of peak_force, rms_torque")


def epsilon_problem(problem: StudyProblem, name: str, epsilon: float, scale: float) -> StudyProblem:
    """``problem``'s study with criterion ``name`` <= ``epsilon`` appended to every task's rows.

    The same variables, scaling (each task's cost scale is ``problem``'s) and rows, then the epsilon
    block of each task (``extra_blocks``: this problem's own, the block registry untouched).
    """
    return StudyProblem(
        problem.study,
        problem.emlas,
        problem.id_path,
        tightened=problem.tightened,
        objective=problem.objective.name,
        cost_scales=[p.cost_scale for p in problem.problems],
        extra_blocks=lambda task: [epsilon_block(task, name, epsilon, scale)],
    )

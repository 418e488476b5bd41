"""Constraint blocks and objectives as objects: one block list defines rows, names and the Jacobian."""

from __future__ import annotations

import numpy as np
import pytest
from test_study_small import small_study

from hiab_sim.errors import InvalidInputError
from hiab_sim.study.constraints.blocks import ObjectiveBound
from hiab_sim.study.nlp.interface import ConstraintBlock, DenseRows, Relaxation, SamplePartials, SampleState
from hiab_sim.study.nlp.objectives import SquaredPowerCost, make_objective
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.solvers.slsqp import start_points
from hiab_sim.study.spec.study_file import study_from_dict

STUDY = study_from_dict(small_study(), "small.yaml")


class RmsForceLimit(ConstraintBlock):
    """1 - RMS(f_lift) / limit >= 0 over all samples: an integral row like a thermal RMS-torque limit."""

    name = "rms_force"

    def __init__(self, limit: float) -> None:
        self.limit = limit

    def row_names(self) -> list[str]:
        """One row."""
        return ["rms_force.lift <= limit"]

    def values(self, state: SampleState) -> np.ndarray:
        """1 - sqrt(mean f^2) / limit."""
        return np.array([1.0 - np.sqrt(np.mean(state.actuators.force[:, 0] ** 2)) / self.limit])

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """d/dY = -f / (K rms limit) on the lift force, chained through the ID partials."""
        f = state.actuators.force[:, 0]
        rms = np.sqrt(np.mean(f**2))
        d_f = -f / (len(f) * rms * self.limit)  # (K,)
        dq = d_f[:, None] * partials.id_q[:, 0, :]  # (K, 9)
        dxi = d_f @ partials.id_xi[:, 0, :]  # (6,)
        return DenseRows(dq=dq[None], dxi=dxi[None])

    def relaxation(self, values: np.ndarray) -> Relaxation:
        """Per N of the limit: the row moves by RMS / limit^2 = (1 - g) / limit."""
        return Relaxation(("N",), (1.0 - np.asarray(values)) / self.limit)


class WithRmsBlock(TaskProblem):
    """The small study's NLP with one more block: the only edit is the block list."""

    def _build_blocks(self) -> list[ConstraintBlock]:
        return [*super()._build_blocks(), RmsForceLimit(limit=60e3)]


class WithCostBound(TaskProblem):
    """The small study's NLP with its own cost held below a bound (an epsilon constraint)."""

    def _build_blocks(self) -> list[ConstraintBlock]:
        cost = SquaredPowerCost(self.emlas, self.dt)
        return [*super()._build_blocks(), ObjectiveBound(cost, bound=5e5, scale=1e5)]


def _point(problem: TaskProblem) -> np.ndarray:
    """A feasible start other than the built crane's (drawn on the plain NLP), with perturbed coefficients."""
    rng = np.random.default_rng(5)
    z = problem.initial_point(start_points(TaskProblem(STUDY, id_path="analytic"), 2)[1])
    return z + np.concatenate([np.zeros(6), rng.normal(0.0, 0.02, problem.n_c)])


def test_every_row_belongs_to_one_named_block() -> None:
    """Block slices tile the rows in order, each row is named after its block, and values match names."""
    problem = TaskProblem(STUDY, id_path="analytic")
    ev = problem.evaluate(problem.initial_point(STUDY.initial_lengths))
    layout = problem.layout
    stop = 0
    for block in layout.blocks:
        rows = layout.slices[block.name]
        assert rows.start == stop
        stop = rows.stop
        assert len(block.values(ev)) == rows.stop - rows.start
        assert all(name.startswith(block.name + ".") for name in problem.constraint_names[rows])
    assert stop == len(problem.constraint_names) == len(ev.constraints)
    named = layout.named(ev.constraints)
    assert sum(len(rows) for rows in named.values()) == len(ev.constraints)


def test_clearance_only_tightens_rows_of_xi_alone_and_adds_back_to_the_nominal_rows() -> None:
    """The clearance is >= 0, only on rows independent of the trajectory, and adds back to the nominal rows.

    Solver rows plus the clearance are the nominal problem's rows, for every block the nominal problem has too.
    """
    tight = TaskProblem(STUDY, id_path="analytic")
    z = tight.initial_point(STUDY.initial_lengths)
    assert np.all(tight.clearance >= 0.0) and np.any(tight.clearance > 0.0)
    jac = tight.constraints_jacobian(z)
    cleared = tight.clearance > 0.0
    assert np.all(jac[cleared][:, tight.n_xi :] == 0.0)  # the cleared rows do not move with the trajectory
    loose = TaskProblem(STUDY, id_path="analytic", tightened=False)
    for block in tight.layout.blocks:
        if block.name not in loose.layout.slices or not np.any(tight.layout.split(tight.clearance)[block.name]):
            continue
        rows, nominal = tight.layout.slices[block.name], loose.layout.slices[block.name]
        np.testing.assert_allclose(tight.margins(z)[rows], loose.constraints(z)[nominal], rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    ("kind", "last_row"),
    [(WithRmsBlock, "rms_force.lift <= limit"), (WithCostBound, "bound.costf2 <= 500000 W^2 s")],
    ids=["rms_force", "cost_bound"],
)
def test_an_added_integral_block_gets_an_exact_jacobian(kind: type[TaskProblem], last_row: str) -> None:
    """A row that depends on every sample (RMS force, a cost bound) enters D g / dz and matches central differences."""
    problem = kind(STUDY, id_path="analytic")
    assert problem.constraint_names[-1] == last_row
    z = _point(problem)
    row = problem.constraints_jacobian(z)[-1]
    fd = np.zeros(problem.n)
    for i in range(problem.n):
        h = 1e-6 if i < 6 else 1e-5
        up, down = z.copy(), z.copy()
        up[i] += h
        down[i] -= h
        fd[i] = (problem.constraints(up)[-1] - problem.constraints(down)[-1]) / (2 * h)
    np.testing.assert_allclose(row, fd, atol=1e-6 * np.max(np.abs(fd)), rtol=1e-4)
    # the other rows are those of the plain problem
    plain = TaskProblem(STUDY, id_path="analytic")
    np.testing.assert_array_equal(problem.constraints(z)[:-1], plain.constraints(z))


def test_cost_bound_row_is_the_bound_less_the_problem_cost() -> None:
    """The epsilon row equals (bound - f) / scale with f the problem's own (unscaled) cost at the same point."""
    problem = WithCostBound(STUDY, id_path="analytic")
    z = _point(problem)
    assert problem.constraints(z)[-1] == pytest.approx((5e5 - problem.evaluate(z).cost) / 1e5, rel=1e-14)


def test_unknown_objective_names_the_field() -> None:
    """An objective name outside the registry is rejected with the field ``objective``."""
    problem = TaskProblem(STUDY, id_path="analytic")
    with pytest.raises(InvalidInputError, match="objective"):
        make_objective("fastest", problem.emlas, problem.dt)

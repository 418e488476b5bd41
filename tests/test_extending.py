"""A new objective and a new constraint block registered from this file alone run through every study path.

The objective and the block below are the example of docs/extending.md: a squared-force integral
[N^2 s] and a floor under the TCP [m]. Registered here, they serve a single-task and a two-task
study, the sensitivities (in the objective's own unit) and the report, with no edit of the package.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from test_mix import two_tasks
from test_study_small import small_study

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaSet
from hiab_sim.study.constraints.block_registry import register_block, unregister_block
from hiab_sim.study.nlp.interface import (
    PerSampleBlock,
    Relaxation,
    SamplePartials,
    SampleRows,
    SampleState,
)
from hiab_sim.study.nlp.objectives import register_objective, unregister_objective
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.run import run_study
from hiab_sim.study.spec.study_file import study_from_dict

# --- the example of docs/extending.md -----------------------------------------------------------


class SquaredForceCost:
    """f = 1/2 Dt sum_k sum_i f_x,i(t_k)^2 [N^2 s]: the actuators' squared rod forces, a rectangle sum."""

    name = "squared_force"
    unit = "N^2 s"
    measured_by: ClassVar[str | None] = None  # no energy measures it: compare reports the net electrical energy

    def __init__(self, emlas: EmlaSet, dt: float) -> None:
        self.dt = dt

    def value(self, state: SampleState) -> float:
        """1/2 Dt sum f^2 [N^2 s]."""
        return 0.5 * self.dt * float(np.sum(state.actuators.force**2))

    def gradient(self, state: SampleState, partials: SamplePartials) -> tuple[Array, Array]:
        """Dt f_i df_i/d(q9, Xi) through the inverse dynamics' partials (rows 0-2 of Y are the forces)."""
        dY = np.zeros((len(state.joints.time), 9))
        dY[:, :3] = self.dt * state.actuators.force
        return np.einsum("ky,kyq->kq", dY, partials.id_q), np.einsum("ky,kyx->x", dY, partials.id_xi)


#: Scale of the floor rows [m per unit].
FLOOR_SCALE = 0.1


class TcpFloor(PerSampleBlock):
    """(y_tcp - floor) / FLOOR_SCALE >= 0 at every sample: the TCP stays above a floor [m]."""

    def __init__(self, times: Array, floor: float) -> None:
        self.name = "tcp_floor"
        self.times = times
        self.floor = floor
        self.sample_rows = ("y_tcp >= floor",)

    def values(self, state: SampleState) -> Array:
        """Height above the floor, scaled, (K,)."""
        return (state.tcp.position[:, 1] - self.floor) / FLOOR_SCALE

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """dy_tcp/dq9 / FLOOR_SCALE (the TCP kinematics' exact partials), (K, 1, 9)."""
        return SampleRows(state.tcp.d_position[:, 1:2, :] / FLOOR_SCALE)

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm the floor is lowered: 1e-3 / FLOOR_SCALE."""
        return Relaxation.uniform("mm", 1e-3 / FLOOR_SCALE, len(values))


def floor_blocks(problem: object) -> list[TcpFloor]:
    """One floor 5 mm under the task's lowest reference point (active where the spiral dips lowest)."""
    return [TcpFloor(problem.times, float(problem.reference.position[:, 1].min()) - 0.005)]  # type: ignore[attr-defined]


# -------------------------------------------------------------------------------------------------


@pytest.fixture
def registered() -> Iterator[None]:
    register_objective("squared_force", SquaredForceCost)
    register_block("tcp_floor", floor_blocks)
    yield
    unregister_block("tcp_floor")
    unregister_objective("squared_force")


def test_registered_objective_and_block_enter_the_nlp_with_exact_derivatives(registered: None) -> None:
    """The study loads ``objective: squared_force``; the floor rows appear per sample; the gradients match FD."""
    study = study_from_dict({**small_study(), "objective": "squared_force"}, "x.yaml")
    problem = StudyProblem(study)
    names = [n for n in problem.constraint_names if n.startswith("tcp_floor.")]
    assert len(names) == len(problem.problems[0].times)
    z = problem.initial_point(study.initial_lengths) + 1e-3
    grad, jac = problem.cost_gradient(z), problem.constraints_jacobian(z)
    rows = np.array([i for i, n in enumerate(problem.constraint_names) if n.startswith("tcp_floor.")])
    h = 1e-6
    for j in (0, 3, 10, 40):
        e = np.zeros_like(z)
        e[j] = h
        fd_cost = (problem.cost(z + e) - problem.cost(z - e)) / (2 * h)
        fd_rows = (problem.constraints(z + e)[rows] - problem.constraints(z - e)[rows]) / (2 * h)
        assert grad[j] == pytest.approx(fd_cost, rel=1e-5, abs=1e-9)
        np.testing.assert_allclose(jac[rows, j], fd_rows, rtol=1e-5, atol=1e-8)


@pytest.mark.e2e
@pytest.mark.parametrize("tasks", [1, 2])
def test_registered_objective_and_block_run_a_study_with_sensitivities_and_report(
    registered: None, tmp_path: Path, tasks: int
) -> None:
    """One and two tasks: optimised, the floor held, sensitivities in N^2 s, the report names the objective."""
    data = small_study() if tasks == 1 else two_tasks()
    study = study_from_dict({**data, "objective": "squared_force"}, "x.yaml")
    out = run_study(study, tmp_path / "run", progress=None, figures=False, cross=False)
    r = out.result
    assert r.solver.success
    assert r.energy is not None and r.energy.objective == "squared_force"
    assert r.history[-1].cost < r.history[0].cost  # the squared force went down
    assert r.optimal.max_violation <= 1e-6
    s = r.sensitivity
    assert s is not None and s.objective == "squared_force" and s.objective_unit == "N^2 s"
    assert s.objective_value == pytest.approx(r.history[-1].cost, rel=1e-9)
    floors = [m for m in s.multipliers if "tcp_floor." in m.constraint]
    for m in floors:
        assert m.unit == "mm" and m.objective_decrease_per_unit > 0.0
        assert m.percent_per_unit == pytest.approx(100.0 * m.objective_decrease_per_unit / s.objective_value)
    assert r.buildable is not None and r.buildable.recheck.passed
    assert (tmp_path / "run" / "result.json").read_text().count("tcp_floor") >= (1 if floors else 0)


def test_unknown_objective_is_one_line_naming_the_field_and_the_registered_names(registered: None) -> None:
    """``objective: fastest`` fails naming ``objective`` and every registered name, the new one included."""
    from hiab_sim.errors import InvalidInputError

    with pytest.raises(InvalidInputError) as info:
        study_from_dict({**small_study(), "objective": "fastest"}, "x.yaml")
    message = str(info.value)
    assert "\n" not in message and "objective" in message
    for name in ("costf2", "battery_energy", "squared_force"):
        assert name in message


def test_a_violated_registered_row_is_described_in_its_own_unit(registered: None) -> None:
    """The feasibility phase's message names a registered block's row and its violation in the block's unit."""
    from hiab_sim.study.solvers.feasibility import describe_violation

    problem = StudyProblem(study_from_dict(small_study(), "x.yaml"))
    index = next(i for i, n in enumerate(problem.constraint_names) if n.startswith("tcp_floor."))
    # scaled row -0.01 = 1 mm below the floor (FLOOR_SCALE 0.1 m per unit)
    text = describe_violation(problem, index, -0.01)
    assert text.startswith("tcp_floor.y_tcp >= floor") and text.endswith("violated by 1 mm")


class DrawnForceCost(SquaredForceCost):
    """The example objective claiming an energy no result gives for every design (the energy drawn)."""

    measured_by = "drawn_energy"


def test_an_objective_must_declare_the_energy_that_measures_it() -> None:
    """A factory without ``measured_by``, or naming no result energy, is refused in one line naming the field."""
    from hiab_sim.errors import InvalidInputError
    from hiab_sim.study.nlp.objectives import OBJECTIVES

    for factory, shown in ((lambda emlas, dt: SquaredForceCost(emlas, dt), "'(not declared)'"),
                           (DrawnForceCost, "'drawn_energy'")):  # fmt: skip
        with pytest.raises(InvalidInputError) as info:
            register_objective("undeclared", factory)
        assert str(info.value) == (
            f"objective undeclared: measured_by = {shown} is out of range: must be None (no energy measures it) "
            "or one of net_electrical_energy, battery_energy"
        )
    assert "undeclared" not in OBJECTIVES

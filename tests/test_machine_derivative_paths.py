"""Where a machine study takes its derivatives: joint partials on either ID path, stroke partials at any design.

``solver.joint_derivatives`` picks the path of dID/d(q, dq, ddq); unset, a machine file takes the
analytic (Newton-Euler) path and a crane file the optimisation's own. The two paths are independent
implementations, so their finite-difference partials must agree. The stroke rows' chains and partials
are cached per chain: what was asked before must not change what comes back.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from machine_result_helper import EXCAVATOR_STUDY, joint_csv
from test_machine_study import _machine_form

from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.machines.machine_model import MachineModel
from hiab_sim.study.nlp.id_partials import id_joint_partials
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.spec.study_file import load_study

REPO = Path(__file__).resolve().parents[1]


def _excavator(folder: Path, solver: dict[str, object] | None = None) -> StudyProblem:
    joint_csv(folder / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    top = dict(EXCAVATOR_STUDY) | ({"solver": solver} if solver else {})
    (folder / "study.yaml").write_text(yaml.safe_dump(top), encoding="utf-8")
    return StudyProblem(load_study(folder / "study.yaml"))


def test_joint_derivatives_default_to_the_analytic_path_on_a_machine_file_and_the_own_path_on_a_crane_file(
    tmp_path: Path,
) -> None:
    """Unset: the machine file's partials on Newton-Euler, the crane file's on MuJoCo (its id_path); set: as set."""
    crane = StudyProblem(load_study(REPO / "optimize" / "xs031_spiral.yaml"))
    assert crane.id_path == "mujoco" and crane.problems[0].q_path == "mujoco"
    machine_file = tmp_path / "machine.yaml"
    machine_file.write_text(_machine_form((REPO / "optimize" / "xs031_spiral.yaml").read_text()), encoding="utf-8")
    machine = StudyProblem(load_study(machine_file))
    assert machine.id_path == "mujoco" and machine.problems[0].q_path == "analytic"
    own = _excavator(tmp_path, {"joint_derivatives": "path"})
    assert own.problems[0].q_path == "mujoco"


def test_joint_partials_of_the_two_id_paths_agree_on_the_excavator(tmp_path: Path) -> None:
    """dID/d(q, dq, ddq) by central differences on MuJoCo (loop projection) and on Newton-Euler agree."""
    problem = _excavator(tmp_path)
    task = problem.problems[0]
    z = task.initial_point(problem.study.initial_lengths)
    z = z + 1e-3 * np.random.default_rng(5).standard_normal(len(z)) * (np.arange(len(z)) >= task.n_xi)
    ev = task.evaluate(z)
    samples = JointSamples(ev.joints.position, ev.joints.velocity, ev.joints.acceleration)
    analytic = task.joint_partials(ev.lengths, samples)  # the default on a machine file
    mujoco = id_joint_partials(task.model.inverse_dynamics(ev.lengths, "mujoco"), samples, task.fd_step, task.tcp_force)
    assert analytic.shape == mujoco.shape == (len(task.times), 9, 9)
    # per output (force, velocity, acceleration of each actuator): relative to its largest partial
    scale = np.max(np.abs(mujoco), axis=(0, 2), keepdims=True)
    assert np.max(np.abs(analytic - mujoco) / scale) < 1e-6
    assert np.max(np.abs(mujoco)) > 1.0  # not all zero


def test_bad_joint_derivatives_setting_names_the_field(tmp_path: Path) -> None:
    """An unknown path is one line naming solver.joint_derivatives and the allowed values."""
    with pytest.raises(InvalidInputError, match=r"solver\.joint_derivatives.*path, analytic"):
        _excavator(tmp_path, {"joint_derivatives": "fast"})


def test_stroke_partials_at_a_design_do_not_depend_on_the_designs_asked_before(tmp_path: Path) -> None:
    """Cached per chain, yet A, B (one chain's variable moved), A give what a fresh model gives.

    And B's partials in Xi match central differences of B's stroke margins.
    """
    model = _excavator(tmp_path).model
    assert isinstance(model, MachineModel)
    a = model.machine_at(model.design(model.machine.design_values())).design_values()
    b = a.copy()
    b[len(b) - 1] += 2e-3  # the last chain's last variable
    ranges = np.array(model.joint_ranges())
    q = np.linspace(ranges[:, 0], ranges[:, 1], 7)  # (7, n) over every joint's range
    used = MachineModel(model.machine, model.extra)
    for values in (a, b, a):
        fresh = MachineModel(model.machine, model.extra)
        design = model.design(values)
        for got, want in zip(
            used.stroke_margin_partials(design, q), fresh.stroke_margin_partials(design, q), strict=True
        ):
            np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(used.stroke_margins(design, q), fresh.stroke_margins(design, q))
    _, dxi = used.stroke_margin_partials(model.design(b), q)
    for k in range(len(b)):
        h = 1e-6
        up, down = b.copy(), b.copy()
        up[k] += h
        down[k] -= h
        fd = (used.stroke_margins(model.design(up), q) - used.stroke_margins(model.design(down), q)) / (2 * h)
        np.testing.assert_allclose(dxi[:, :, k], fd, rtol=1e-6, atol=1e-8)

"""Every study shipped in optimize/ loads, reaches its reference and starts feasible."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hiab_sim.crane.kinematics import tcp_position
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.solvers.slsqp import START_TOLERANCE, check_start
from hiab_sim.study.spec.study_file import load_study

STUDIES = sorted((Path(__file__).resolve().parents[1] / "optimize").glob("*spiral*.yaml"))
#: The start each shipped study documents: the built XS 031 (lengths omitted) or the seed paper's own.
STARTS = {
    "xs031_spiral": None,
    "xs031_spiral_payload": None,
    "seed_scale_spiral": [1.75, 0.544, 1.27, 1.75, 0.55, 1.2],
}


def test_the_shipped_studies_are_found() -> None:
    """The default, payload and seed-scale studies are all in optimize/."""
    assert {p.name for p in STUDIES} >= {"xs031_spiral.yaml", "xs031_spiral_payload.yaml", "seed_scale_spiral.yaml"}


@pytest.mark.parametrize("path", STUDIES, ids=lambda p: p.stem)
def test_shipped_study_starts_feasible_on_its_documented_start(path: Path) -> None:
    """The study is named after its file, starts where its comments say, and that start meets every constraint."""
    study = load_study(path)
    assert study.name == path.stem  # its default output folder is runs/<file stem>
    expected = STARTS.get(path.stem)
    start = study.crane.default_lengths.as_array() if expected is None else np.array(expected)
    np.testing.assert_array_equal(study.initial_lengths.as_array(), start)
    problem = TaskProblem(study)
    z0 = problem.initial_point(study.initial_lengths)
    check_start(problem, z0)
    assert problem.max_violation(z0) <= START_TOLERANCE


@pytest.mark.parametrize("path", STUDIES, ids=lambda p: p.stem)
def test_shipped_study_reference_is_tracked_by_its_start(path: Path) -> None:
    """Forward kinematics of the start's joints puts the TCP on the reference within the band held at collocation.

    The start's spline is fitted to the reference by inverse kinematics; the crane's own forward
    kinematics (not the problem's tracked coordinates) must reproduce the reference TCP and the
    prescribed telescope extension xt2 within tracking.position x collocation_fraction.
    """
    study = load_study(path)
    problem = TaskProblem(study)
    ev = problem.evaluate(problem.initial_point(study.initial_lengths))
    theta1, theta2, xt2 = ev.joints.position.T
    tcp = tcp_position(study.crane, theta1, theta2, xt2)
    reference = problem.reference.tcp()
    held = study.tracking.position * study.tracking.collocation_fraction
    assert np.max(np.linalg.norm(tcp[:, :2] - reference[:, :2], axis=1)) <= np.sqrt(2.0) * held
    assert np.max(np.abs(xt2 - problem.reference.position[:, 2])) <= held
    assert np.ptp(reference[:, 0]) > 0.05 and np.ptp(reference[:, 1]) > 0.05  # a real spiral, not a point
    if study.payload:
        assert study.payload == pytest.approx(150.0) and path.stem.endswith("payload")

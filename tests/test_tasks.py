"""Tasks of a study: today's single reference is one task; ``tasks:`` lists several, checked when read."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.references.csv_file import CsvReference
from hiab_sim.study.references.kinds import PickAndPlace, Spiral
from hiab_sim.study.spec.study_file import load_study
from hiab_sim.study.spec.tasks import check_tasks, column_names, tasks_from_mapping

OPTIMIZE = Path(__file__).resolve().parents[1] / "optimize"
MIX = yaml.safe_load((OPTIMIZE / "xs031_duty_mix.yaml").read_text())
STUDY = load_study(OPTIMIZE / "xs031_spiral_payload.yaml")
KIN = tr.TcpKinematics(STUDY.crane)


def _tasks(top: dict) -> tuple:
    return tasks_from_mapping(top, OPTIMIZE, 6.25, "study", column_names(STUDY.model))


def test_single_reference_study_is_one_task_with_the_studys_spiral_and_payload() -> None:
    """Today's ``reference:`` + ``payload: 150`` read as one task: the loader's spiral, a constant 150 kg."""
    top = yaml.safe_load((OPTIMIZE / "xs031_spiral_payload.yaml").read_text())
    (task,) = tasks_from_mapping(top, OPTIMIZE, STUDY.grid.duration, STUDY.name, column_names(STUDY.model))
    assert task.name == STUDY.name and task.weight == 1.0 and isinstance(task.reference, Spiral)
    assert task.payload.mass == STUDY.payload and task.payload.pick is None and task.payload.release is None
    times = STUDY.grid.times()
    assert task.spline_points(22, 6.25, 5) == STUDY.spline.control_points
    np.testing.assert_allclose(task.times(STUDY.grid.dt), times, atol=1e-12)
    force = task.tcp_force(KIN, STUDY.crane.gravity, times)
    weight = np.array([0.0, -150.0 * STUDY.crane.gravity, 0.0])
    assert force is not None
    np.testing.assert_allclose(force[[0, -1]], np.tile(weight, (2, 1)), atol=1e-9)  # at rest: the weight
    # a plain number in this form keeps today's meaning: the weight only, no inertia (as the study loader reads it)
    assert task.payload.inertia is False and STUDY.tasks[0].payload == task.payload
    held = STUDY.tasks[0].id_force(KIN, STUDY.crane.gravity, times)
    assert held is not None and held.shape == (3,)
    np.testing.assert_array_equal(held, weight)


def test_duty_mix_reads_three_reachable_tasks() -> None:
    """The duty mix gives the spiral, the pick-and-place and the CSV cycle, all reachable."""
    tasks = _tasks(MIX)
    assert [type(t.reference) for t in tasks] == [Spiral, PickAndPlace, CsvReference]
    assert [t.weight for t in tasks] == [10.0, 20.0, 30.0]
    assert [t.payload.mass for t in tasks] == [0.0, 200.0, 300.0]
    check_tasks(tasks, KIN, STUDY.crane)
    assert tasks[0].tcp_force(KIN, 9.81, np.zeros(3)) is None
    assert [t.spline_points(22, 6.25, 5) for t in tasks] == [22, 30, 100]


def test_payload_force_of_a_task_is_zero_before_pick_weight_while_resting_and_zero_after_release() -> None:
    """Pick-and-place with its payload: no force before pick, exactly m g at rest holding it, none after release."""
    task = _tasks(MIX)[1]
    times = np.array([0.5, 1.0, 14.0, 14.5])  # dwell at pick (before, after pick); dwell at place (before, after)
    force = task.tcp_force(KIN, 9.8066, times)
    assert force is not None
    np.testing.assert_allclose(force[:, 1], [0.0, -200.0 * 9.8066, -200.0 * 9.8066, 0.0], atol=1e-9)


def _mix_with(change: dict, index: int = 1) -> dict:
    top = copy.deepcopy(MIX)
    top["tasks"][index] |= change
    return top


@pytest.mark.parametrize(
    ("top", "error", "match"),
    [
        (MIX | {"reference": {}}, ConfigError, "either 'tasks:' or 'reference:'"),
        (MIX | {"tasks": []}, ConfigError, "non-empty list"),
        (_mix_with({"name": "spiral"}), ConfigError, "'spiral' is used twice"),
        (_mix_with({"weight": 0.0}), InvalidInputError, r"tasks\[1\].weight = 0 is out of range"),
        (_mix_with({"payload": {"mass": 200.0, "pick": 1.0, "release": 30.0}}), InvalidInputError, r"release = 30 s"),
        (_mix_with({"payload": -5.0}), InvalidInputError, r"tasks\[1\].payload.mass = -5 kg"),
        (_mix_with({"control_points": 3}), InvalidInputError, r"tasks\[1\].control_points"),
        (_mix_with({"colour": "red"}), ConfigError, r"tasks\[1\]: unknown key"),
        (_mix_with({"reference": {"kind": "csv", "file": "missing.csv"}}), ConfigError, "missing.csv"),
    ],
    ids=["both-forms", "empty", "duplicate-name", "weight", "release-late", "mass", "control-points", "key", "csv"],
)
def test_bad_task_list_raises_naming_the_task(top: dict, error: type, match: str) -> None:
    """Every bad task raises one error naming the task (its index) and the field."""
    with pytest.raises(error, match=match):
        _tasks(top)


def test_unreachable_task_names_the_task_and_time() -> None:
    """A pick-and-place beyond the crane's reach names the task, its index and the time."""
    top = _mix_with({"reference": MIX["tasks"][1]["reference"] | {"place": [5.5, 0.2]}})
    with pytest.raises(InvalidInputError, match=r"tasks\[1\] \(pick_and_place\) reference at t = [\d.]+ s"):
        check_tasks(_tasks(top), KIN, STUDY.crane)

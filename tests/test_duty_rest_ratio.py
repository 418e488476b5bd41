"""The duty's ``rest_ratio``: each task rests r times its own cycle time; read, refused when bad, as a rest_time."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.emla.thermal import Duty
from hiab_sim.errors import HiabSimError
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.spec.energy import DutySettings, energy_settings
from hiab_sim.study.spec.study_file import study_from_dict

FLAGS = ["--no-video", "--quiet", "--no-figures"]
#: Two spirals of different durations [s] (the small study's spiral, slowed for the second).
DURATIONS = (6.25, 9.0)


def _mix(duty: dict[str, Any]) -> dict[str, Any]:
    """The small study as a mix of two spirals of DURATIONS, battery-energy objective, the given duty."""
    reference = small_study()["reference"]
    tasks = [
        {"name": f"spiral_{k}", "weight": 1.0 + k, "reference": {"kind": "spiral", **reference, "duration": T}}
        for k, T in enumerate(DURATIONS)
    ]
    study = small_study(objective="battery_energy", duty=duty)
    del study["reference"]
    return {**study, "tasks": tasks}


def _single(duration: float, duty: dict[str, Any]) -> dict[str, Any]:
    """The small study's spiral alone over ``duration`` [s] with the given duty."""
    study = small_study(objective="battery_energy", duty=duty)
    study["reference"] = {**study["reference"], "duration": duration}
    return study


def test_rest_ratio_is_read_and_rests_its_share_of_each_cycle() -> None:
    """duty: {rest_ratio: 0.2}: the 31.8 s digging cycle rests 6.36 s and the 23.5 s pass 4.70 s (a 50-minute hour)."""
    settings = energy_settings({"duty": {"rest_ratio": 0.2, "hold": "brake"}}).duty
    assert settings == DutySettings(rest_ratio=0.2, hold="brake")
    assert settings.duty(31.8) == Duty(31.8, 6.36)
    assert settings.duty(23.5) == Duty(23.5, 4.70)
    assert settings.duty(23.5).period * 5 / 6 == pytest.approx(23.5, rel=1e-15)  # 50 of every 60 minutes at work
    assert settings.describe(31.8) == "rest 0.2 x the cycle time (31.8 s cycle + 6.36 s rest)"
    assert DutySettings(rest_ratio=0.0).duty(10.0) == Duty(10.0, 0.0)  # back to back


@pytest.mark.parametrize(
    ("duty", "shown"),
    [
        ({"rest_ratio": -0.1}, "duty.rest_ratio = -0.1"),
        ({"rest_ratio": float("nan")}, "duty.rest_ratio = nan"),
        ({"rest_ratio": float("inf")}, "duty.rest_ratio = inf"),
        ({"rest_ratio": "a fifth"}, "duty.rest_ratio"),
        ({"rest_ratio": 0.2, "rest_time": 6.0}, "rest_time and rest_ratio"),
        ({"rest_ratio": 0.2, "cycles_per_hour": 60}, "cycles_per_hour and rest_ratio"),
        ({"hold": "brake"}, "give exactly one of rest_time [s], cycles_per_hour [1/h] or rest_ratio"),
    ],
)
def test_bad_rest_ratio_exits_2_with_one_line_naming_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], duty: dict[str, Any], shown: str
) -> None:
    """A negative, non-finite or non-numeric ratio, or a ratio with another rest key: exit 2, one line, no output."""
    study = write_study(tmp_path, small_study(duty=duty))
    out = tmp_path / "out"
    assert main(["optimize", str(study), "--out", str(out), *FLAGS]) == 2
    err = capsys.readouterr().err.strip()
    assert shown in err and len(err.splitlines()) == 1 and "Traceback" not in err
    assert not out.exists()
    with pytest.raises(HiabSimError, match="duty"):
        study_from_dict(small_study(duty=duty), tmp_path / "s.yaml")


def _raw(study: dict[str, Any], task: int = 0) -> tuple[float, np.ndarray]:
    """Battery energy [J] and the scaled rows of one task's problem at its start (cost unscaled)."""
    s = study_from_dict(study, "small.yaml")
    problem = TaskProblem(s, cost_scale=1.0, task=s.tasks[task])
    z = problem.initial_point(s.initial_lengths)
    evaluation = problem.evaluate(z)
    return float(evaluation.cost), np.asarray(evaluation.constraints)


def test_each_task_of_a_mix_with_rest_ratio_equals_its_study_with_rest_time_r_times_its_duration() -> None:
    """A mix with rest_ratio 0.5: each spiral's energy and rows equal its own study's with rest_time 0.5 T_k.

    One rest_time cannot stand in for the ratio: the longer spiral's energy with the shorter one's
    rest (3.125 s instead of 4.5 s) differs, so the comparison sees the rest.
    """
    ratio = 0.5
    mix = _mix({"rest_ratio": ratio, "hold": "brake"})
    for k, duration in enumerate(DURATIONS):
        cost, rows = _raw(mix, task=k)
        same_cost, same_rows = _raw(_single(duration, {"rest_time": ratio * duration, "hold": "brake"}))
        assert cost == same_cost
        np.testing.assert_array_equal(rows, same_rows)
    other_cost, _ = _raw(_single(DURATIONS[1], {"rest_time": ratio * DURATIONS[0], "hold": "brake"}))
    assert other_cost != pytest.approx(_raw(mix, task=1)[0], rel=1e-9)

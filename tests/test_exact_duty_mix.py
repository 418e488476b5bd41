"""optimize/exact_duty_mix.yaml: the single excavator studies' two tasks, one mounting, the weights it derives."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from hiab_sim.study.spec.study_file import load_study

OPTIMIZE = Path(__file__).resolve().parents[1] / "optimize"
MIX = load_study(OPTIMIZE / "exact_duty_mix.yaml")
SINGLE = {name: load_study(OPTIMIZE / f"exact_{name}.yaml") for name in ("digging", "grading")}


@pytest.mark.parametrize("name", sorted(SINGLE))
def test_each_task_of_the_mix_is_its_single_studys_task(name: str) -> None:
    """Same reference samples, soil, payload, control points and duty period as exact_<task>.yaml (weight aside)."""
    task = next(t for t in MIX.tasks if t.name == name)
    (alone,) = SINGLE[name].tasks
    assert (task.payload, task.soil, task.control_points) == (alone.payload, alone.soil, alone.control_points)
    assert task.reference.duration == alone.reference.duration
    times = np.linspace(0.0, alone.reference.duration, 400)
    got, want = task.reference.sample(MIX.model.kinematics, times), alone.reference.sample(MIX.model.kinematics, times)
    np.testing.assert_array_equal(got.position, want.position)
    assert replace(task, weight=1.0, reference=alone.reference) == alone
    single = SINGLE[name]
    assert MIX.energy.duty is not None and single.energy.duty is not None
    assert MIX.energy.duty.duty(task.reference.duration) == single.energy.duty.duty(alone.reference.duration)
    shared = ("spline", "grid", "tracking", "bounds", "emlas", "tracked", "initial_lengths")
    assert all(getattr(MIX, key) == getattr(single, key) for key in shared)
    assert MIX.energy.objective == single.energy.objective == "battery_energy"


def test_the_weights_are_three_digging_cycles_per_grading_pass_filling_the_hour() -> None:
    """Two 120 mm x 0.80 m x 0.40 m cuts per 0.48 m^2 pass: 3 cycles per pass; with the rests, 3600 s of the hour."""
    weight = {t.name: t.weight for t in MIX.tasks}
    cycles_per_pass = 2 * 1.20 / 0.80  # two layers, each cut 0.80 m long, a pass 1.20 m long, both 0.40 m wide
    assert weight["digging"] / weight["grading"] == pytest.approx(cycles_per_pass, rel=1e-3)
    assert MIX.energy.duty is not None
    periods = sum(t.weight * MIX.energy.duty.duty(t.reference.duration).period for t in MIX.tasks)
    assert periods == pytest.approx(3600.0, rel=1e-4)
    work = sum(t.weight * t.reference.duration for t in MIX.tasks)
    assert work == pytest.approx(3000.0, rel=1e-4)  # the 50-minute working hour

"""``hiab-sim simulate``'s runs: without a video each run's Physics is freed when the run ends; the help's files.

The closed loops are stand-ins (no MuJoCo): what is checked is how many simulation models are alive
when each run starts, which on a long duty mix (tasks x designs x end masses) is the memory held.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from hiab_sim.cli import main


class _Models:
    """Stand-in Physics that count themselves: ``live`` the unfreed ones, ``at_start`` the count as each run began."""

    def __init__(self) -> None:
        self.live: list[object] = []
        self.at_start: list[int] = []

    def run(self, plan: Any, *args: Any, **kwargs: Any) -> tuple[SimpleNamespace, object]:
        """A closed loop's stand-in: a run of ``plan``'s design and task, and a Physics that frees itself."""
        self.at_start.append(len(self.live))
        live = self.live
        model = SimpleNamespace()
        model.free = lambda: live.remove(model)
        live.append(model)
        return SimpleNamespace(design=plan.design, task=plan.task), model


def _plan(result_dir: object, design: str, task: int | None = None) -> SimpleNamespace:
    """A plan's stand-in: its design and its task's name."""
    return SimpleNamespace(design=design, task=None if task is None else f"task {task}")


@pytest.mark.parametrize("keep", [False, True])
def test_a_crane_mix_without_a_video_holds_one_physics_at_a_time(monkeypatch: pytest.MonkeyPatch, keep: bool) -> None:
    """3 tasks x 2 designs x 2 end masses: without a video no run starts with another's Physics alive.

    For a video the runs at the end mass asked for keep theirs (returned to render), the nominal runs' are freed.
    """
    from hiab_sim.env import validation

    models = _Models()
    monkeypatch.setattr(validation, "run_closed_loop", models.run)
    plans = [_plan("result", design, task) for task in (0, 1, 2) for design in ("initial", "optimal")]
    runs, nominal, physics = validation.simulate_designs(plans, 0.2, quiet=True, keep_physics=keep)  # type: ignore[arg-type]
    assert len(runs) == len(nominal) == 6
    if keep:
        assert models.live == physics and len(physics) == 6
    else:
        assert models.at_start == [0] * 12 and models.live == [] and physics == []


def test_a_machine_mix_without_a_video_holds_one_physics_at_a_time(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """A machine file's result: with ``--no-video`` each run's Physics is freed before the next run starts."""
    from hiab_sim.cli import simulate_summary
    from hiab_sim.cli.simulate_machine import run_machine
    from hiab_sim.env import machine_env, machine_plan, validation

    models = _Models()

    def plan(result_dir: object, design: str, task: int | None = None) -> SimpleNamespace:
        machine = SimpleNamespace(realistic_plant=None, name="machine")
        return SimpleNamespace(**vars(_plan(result_dir, design, task)), machine=machine, emlas=None)

    def report(result_dir: object, runs: list[Any], nominal: list[Any], emlas: object = None) -> dict[str, Any]:
        return {"settings": {}, "designs": {run.design: {"bandwidth_check": {"note": ""}} for run in runs}}

    monkeypatch.setattr(machine_plan, "read_machine_plan", plan)
    monkeypatch.setattr(machine_env, "run_machine_closed_loop", lambda plan, **kwargs: models.run(plan))
    monkeypatch.setattr(validation, "simulation_report", report)
    monkeypatch.setattr(simulate_summary, "write_results", lambda *args: ([], None))
    monkeypatch.setattr(simulate_summary, "print_results", lambda *args: None)
    args = argparse.Namespace(
        result_dir="result", payload_error=0.0, plant=None, no_video=True, cycles=1, quiet=True, no_figures=True
    )
    assert run_machine(args, ("initial", "optimal"), tmp_path, (0, 1, 2)) == 0
    assert models.at_start == [0] * 6 and models.live == []


def test_the_help_names_a_duty_mix_s_files(capsys: pytest.CaptureFixture[str]) -> None:
    """``simulate --help`` says a duty mix runs per task and per design and names its per-task video."""
    with pytest.raises(SystemExit) as done:
        main(["simulate", "--help"])
    assert done.value.code == 0
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps the lines
    assert "duty mix" in text and "per task and per design" in text
    assert "--no-video skip closed_loop.mp4 (a duty mix: closed_loop_task0.mp4, ... one per task)" in text

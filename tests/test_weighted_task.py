"""One task of weight w (cycles per hour): the result's top level is w times the task, and the task keeps its own.

A study of a single task of weight 1 is today's single-reference study (its sections are the task's
own); any other weight makes the top-level energies weighted sums, like a mix's, so the task's own
cycle must stay readable (``result.json`` ``tasks``, ``trajectory.npz`` ``task0_*``) for everything
that compares one cycle, such as the closed loop.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from test_study_small import TINY, small_study, write_study

from hiab_sim.cli import main
from hiab_sim.results.read import read_result

WEIGHT = 20.0  # cycles per hour


@pytest.fixture(scope="module")
def weighted_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tiny study as one task of weight 20, optimised (a few seconds)."""
    from hiab_sim.study.run import run_study
    from hiab_sim.study.spec.study_file import load_study

    folder = tmp_path_factory.mktemp("weighted")
    data = small_study(**TINY)
    data["tasks"] = [{"name": "spiral", "weight": WEIGHT, "reference": {"kind": "spiral", **data.pop("reference")}}]
    run_study(load_study(write_study(folder, data)), folder / "result", figures=False, progress=None, cross=False)
    return folder / "result"


def test_one_weighted_task_keeps_its_own_cycle_beside_the_weighted_sum(weighted_run: Path) -> None:
    """The top-level net energy is w times the task's own, which result.json keeps under tasks."""
    result = read_result(weighted_run)
    assert result.tasks is not None and len(result.tasks) == 1
    task = result.tasks[0]
    assert result.optimal.net_electrical_energy_J == pytest.approx(
        WEIGHT * task.optimal.net_electrical_energy_J, rel=1e-12
    )


@pytest.mark.sim
def test_closed_loop_of_one_weighted_task_is_compared_with_its_own_cycle(
    weighted_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The closed loop compares the one cycle it runs with the task's own planned energy (within 1 %), not w cycles."""
    args = ["simulate", str(weighted_run), "--design", "optimal", "--out", str(tmp_path), "--no-video", "--quiet"]
    assert main(args) == 0
    capsys.readouterr()
    report = json.loads((tmp_path / "simulation.json").read_text(encoding="utf-8"))
    planned = read_result(weighted_run).tasks[0].optimal.net_electrical_energy_J  # type: ignore[index]
    entry = report["tasks"][0]["designs"]["optimal"]
    assert entry["predicted_net_electrical_energy_J"] == planned
    assert entry["net_electrical_energy_J"] == pytest.approx(planned, rel=0.01)


def test_one_weighted_tasks_energy_line_says_it_is_w_times_a_cycle_and_gives_the_cycle(weighted_run: Path) -> None:
    """The summary's energy line calls the top-level number weight x the cycle (per hour) and prints the cycle too."""
    from hiab_sim.study.report.energy_section import energy_lines
    from hiab_sim.study.report.summary import before_after, energy_line

    result = read_result(weighted_run)
    task = result.tasks[0]  # type: ignore[index]
    line = energy_line(result)
    assert f"weight 20 x the energy per cycle of task '{task.name}'" in line and "per hour" in line
    assert "the tasks' weighted sum of each task's energy" not in line
    if result.energy is not None and task.energy is not None:
        cycle = before_after(task.energy.initial.battery_energy_J, task.energy.optimal.battery_energy_J)
        assert "the tasks' weighted sum" in energy_lines(result)[1]
    else:
        cycle = before_after(task.initial.net_electrical_energy_J, task.optimal.net_electrical_energy_J)
    assert line.endswith(f"; per cycle: {cycle}.")


def test_a_crane_files_task_result_says_how_its_telescope_is_set(weighted_run: Path) -> None:
    from hiab_sim.study.report.weighted import TELESCOPE

    assert read_result(weighted_run).tasks[0].telescope == TELESCOPE  # type: ignore[index]

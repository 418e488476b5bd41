"""A duty mix in closed loop: every task simulated on its own plan and compared with its own prediction.

A mix's ``result.json`` holds per task its energies of one cycle (``tasks[k]``) and at the top the
weighted sum over the tasks (per hour where the weights are cycles per hour); ``trajectory.npz`` holds
each task's motion under ``task<k>_``. The closed loop of each task's plan must use that task's
planned energy: the drives' exact per-step integral against the optimiser's quadrature of its
steady-state P_elec, two computations of one quantity. The mixes are small: the crane's two spirals
(the second with a 120 kg payload picked up at 1.5 s and released at 4.5 s, ``test_mix.two_tasks``)
and an excavator's two joint moves (the second with 80 kg held from 0.5 s to 2.0 s).
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from machine_result_helper import EXCAVATOR_STUDY, joint_csv
from test_mix import two_tasks
from test_study_small import write_study

from hiab_sim.cli import main
from hiab_sim.cli.simulate import ENERGY_TOLERANCE, TCP_MAX_MM
from hiab_sim.errors import InvalidInputError

#: The excavator mix: the small excavator study's move, then a 3 s move further up holding 80 kg for 1.5 s.
EXCAVATOR_MIX = {
    **EXCAVATOR_STUDY,
    "name": "excavator_mix",
    "tasks": [
        EXCAVATOR_STUDY["tasks"][0],
        {
            "name": "lift",
            "weight": 2.0,
            "reference": {"kind": "csv", "file": "lift.csv"},
            "payload": {"mass": 80.0, "pick": 0.5, "release": 2.0},
        },
    ],
}


def _solved(folder: Path, study: Path) -> Path:
    """Optimise ``study`` (no figures, no cross-evaluation) into ``folder / "result"``."""
    from hiab_sim.study.run import run_study
    from hiab_sim.study.spec.study_file import load_study

    run_study(load_study(study), folder / "result", figures=False, progress=None, cross=False)
    return folder / "result"


@pytest.fixture(scope="module")
def crane_mix(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The crane's two-task mix optimised (about 2 s)."""
    folder = tmp_path_factory.mktemp("crane_mix")
    return _solved(folder, write_study(folder, two_tasks()))


@pytest.fixture(scope="module")
def excavator_mix(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The excavator's two-task mix optimised (about 2 s)."""
    folder = tmp_path_factory.mktemp("excavator_mix")
    joint_csv(folder / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    joint_csv(folder / "lift.csv", ("alpha", "beta", "gamma"), [0.2, -1.6, -0.6], [0.6, -1.2, -0.2], 3.0)
    (folder / "study.yaml").write_text(yaml.safe_dump(EXCAVATOR_MIX), encoding="utf-8")
    return _solved(folder, folder / "study.yaml")


@pytest.mark.sim
@pytest.mark.parametrize("mix", ["crane_mix", "excavator_mix"])
def test_each_task_of_a_mix_uses_its_own_planned_energy(
    mix: str, request: pytest.FixtureRequest, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Per task: the closed loop within 1 % of the task's own energy, 2 % of its battery energy, on its path.

    Measured: the crane's mix -0.02 % / -0.13 % (battery +0.02 % / -0.27 %), the excavator's +0.01 % /
    -0.04 % (battery -0.06 % / -0.06 %); the weighted sums of the closed loops -0.09 % and -0.02 % from
    the results'.
    """
    from hiab_sim.design_report.analysis import closed_loop
    from hiab_sim.results.read import read_result

    result_dir = request.getfixturevalue(mix)
    args = ["simulate", str(result_dir), "--design", "optimal", "--out", str(tmp_path), "--no-video", "--quiet"]
    assert main(args) == 0
    table = capsys.readouterr().out
    report = json.loads((tmp_path / "simulation.json").read_text(encoding="utf-8"))
    result = read_result(result_dir)
    assert result.tasks is not None and [group["task"] for group in report["tasks"]] == [t.name for t in result.tasks]
    for k, (group, task) in enumerate(zip(report["tasks"], result.tasks, strict=True)):
        entry = group["designs"]["optimal"]
        assert entry["predicted_net_electrical_energy_J"] == task.optimal.net_electrical_energy_J
        assert entry["net_electrical_energy_J"] == pytest.approx(task.optimal.net_electrical_energy_J, rel=0.01)
        assert task.energy is not None
        planned = task.energy.optimal
        battery = planned.battery_energy_J if planned.duty is None else planned.duty.cycle_battery_energy_J
        assert entry["predicted_battery_energy_J"] == battery
        assert entry["battery_energy_J"] == pytest.approx(battery, rel=ENERGY_TOLERANCE)
        assert entry["tcp_error_mm"]["max"] < TCP_MAX_MM
        assert entry["current_limit_fraction"] == 0.0
        assert entry["simulated_time_s"] == pytest.approx(task.duration_s, abs=0.01)
        assert f"| {task.name} | optimal | planned | {task.optimal.net_electrical_energy_J:.1f} |" in table
        assert (tmp_path / f"closed_loop_energy_task{k}.png").is_file()
    weighted = report["mix"]["optimal"]
    assert weighted["net_electrical_energy_J"] == pytest.approx(result.optimal.net_electrical_energy_J, rel=0.01)
    page = closed_loop(tmp_path)  # the design report's section: a row and a figure per task
    assert all(
        f"<td>{task.name}</td><td>optimal</td>" in page and f"of task {task.name}" in page for task in result.tasks
    )


def test_a_mix_plan_needs_its_task(crane_mix: Path) -> None:
    """Reading a mix's plan without a task index, or with one out of range, is refused naming ``task``."""
    from hiab_sim.env.plan import read_plan

    for task in (None, 2, -1):
        with pytest.raises(InvalidInputError, match="task"):
            read_plan(crane_mix, "optimal", task)
    assert read_plan(crane_mix, "optimal", 1).task == "second"


def test_a_task_index_is_any_integer_but_a_bool(crane_mix: Path) -> None:
    """A NumPy integer indexes a mix's tasks as Python's does; True (an int to Python) is refused naming ``task``."""
    from hiab_sim.env.plan import read_plan

    assert read_plan(crane_mix, "optimal", np.int64(1)).task == "second"
    assert read_plan(crane_mix, "optimal", np.uint8(0)).task == "spiral"
    for task in (True, 1.0):
        with pytest.raises(InvalidInputError, match="task"):
            read_plan(crane_mix, "optimal", task)  # type: ignore[arg-type]


def _edited_copy(result_dir: Path, folder: Path, edit: Callable[[list[dict[str, Any]]], None]) -> Path:
    """A copy of ``result_dir`` whose study file (a copy next to it) has had ``edit`` applied to its tasks."""
    shutil.copytree(result_dir.parent, folder)
    study = yaml.safe_load((folder / "study.yaml").read_text(encoding="utf-8"))
    edit(study["tasks"])
    (folder / "study.yaml").write_text(yaml.safe_dump(study), encoding="utf-8")
    result_file = folder / result_dir.name / "result.json"
    result = json.loads(result_file.read_text(encoding="utf-8"))
    result["study"] = str(folder / "study.yaml")
    result_file.write_text(json.dumps(result), encoding="utf-8")
    return folder / result_dir.name


@pytest.mark.parametrize("mix", ["crane_mix", "excavator_mix"])
@pytest.mark.parametrize("edit", ["reordered", "removed"])
def test_a_study_edited_after_the_run_is_refused(
    mix: str, edit: str, request: pytest.FixtureRequest, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A study file whose tasks moved or went since the run is refused in one line naming the file and the task.

    The task's force F(t) comes from the study file by the task's place: reordered, task 1's plan would
    take task 0's force; removed, there is none.
    """
    from hiab_sim.env.machine_plan import read_machine_plan
    from hiab_sim.env.plan import read_plan
    from hiab_sim.errors import ConfigError

    result_dir = request.getfixturevalue(mix)
    copy = _edited_copy(result_dir, tmp_path / "copy", list.reverse if edit == "reordered" else list.pop)
    read = read_plan if mix == "crane_mix" else read_machine_plan
    second = yaml.safe_load((result_dir.parent / "study.yaml").read_text(encoding="utf-8"))["tasks"][1]["name"]
    with pytest.raises(ConfigError, match=rf"study\.yaml.*'?{second}"):
        read(copy, "optimal", 1)
    assert main(["simulate", str(copy), "--out", str(tmp_path / "out"), "--no-video", "--quiet"]) == 2
    error = capsys.readouterr().err
    assert "study.yaml" in error and second in error and "Traceback" not in error and len(error.splitlines()) == 1


def test_a_scheduled_payload_is_the_plans_force(crane_mix: Path) -> None:
    """The second task's plan carries F(t) = m(t) (g - a_ref): zero outside the schedule, weight and inertia within.

    a_ref by central differences of the plan's reference positions (fine grid, 52 ms): within 1 N of 1177 N.
    """
    from hiab_sim.env.plan import read_plan

    plan = read_plan(crane_mix, "optimal", 1)
    assert plan.tcp_force is not None and plan.payload == 120.0
    held = (plan.time >= 1.5) & (plan.time < 4.5)
    assert not plan.tcp_force[~held].any()
    t = plan.time
    acceleration = np.gradient(np.gradient(plan.reference_tcp[:, :2], t, axis=0), t, axis=0)
    expected = 120.0 * (np.array([0.0, -plan.crane.gravity]) - acceleration)
    inside = held & (t > t[2]) & (t < t[-3])  # central differences away from the ends
    np.testing.assert_allclose(plan.tcp_force[inside, :2], expected[inside], atol=1.0)
    assert read_plan(crane_mix, "optimal", 0).tcp_force is None  # the first task carries nothing


def _two_effect_plant(folder: Path) -> Path:
    """The realistic plant with only the sensors and the mass mismatch on (fewer closed loops to run)."""
    from hiab_sim.resources import shipped

    plant = yaml.safe_load(shipped("plant", "realistic").read_text())
    for name, section in plant.items():
        section["enabled"] = name in ("sensors", "mismatch")
    (folder / "two_effects.yaml").write_text(yaml.safe_dump(plant), encoding="utf-8")
    return folder / "two_effects.yaml"


@pytest.mark.sim
def test_the_effect_study_of_a_mix_runs_per_task_on_its_own_plans(crane_mix: Path, tmp_path: Path) -> None:
    """--plant with effects on a mix: per task an effect study on the task's own plans, against its own energies.

    Two code paths reach the ideal variant's closed loop of task k: the effect study and a plain
    ``simulate`` on the ideal plant; their DC-bus energies agree. Each task's mass split starts from
    the task's own prediction (``result.json`` ``tasks[k]``, one cycle), not the mix's weighted sum,
    and the heavier true load costs energy on each task. The mix re-planned for the true masses is
    solved once: every task gets that one design's energy of its own cycle.
    """
    plant = _two_effect_plant(tmp_path)
    common = ["--design", "optimal", "--no-video", "--no-figures", "--quiet"]
    assert main(["simulate", str(crane_mix), "--plant", str(plant), *common, "--out", str(tmp_path / "real")]) == 0
    assert main(["simulate", str(crane_mix), *common, "--out", str(tmp_path / "ideal")]) == 0
    real = json.loads((tmp_path / "real" / "simulation.json").read_text(encoding="utf-8"))
    ideal = json.loads((tmp_path / "ideal" / "simulation.json").read_text(encoding="utf-8"))
    result = json.loads((crane_mix / "result.json").read_text(encoding="utf-8"))
    assert "plant_effects" not in real and len(real["tasks"]) == len(result["tasks"]) == 2
    weighted = {"replanned": 0.0, "nominal at true masses": 0.0}
    for k, (group, plain, planned) in enumerate(zip(real["tasks"], ideal["tasks"], result["tasks"], strict=True)):
        effects = group["plant_effects"]
        assert group["task"] == plain["task"] == planned["name"]
        assert list(effects["variants"]) == ["ideal", "sensors", "mismatch", "all"]
        same = effects["variants"]["ideal"]["optimal"]["dc_bus_energy_J"]
        assert same == pytest.approx(plain["designs"]["optimal"]["dc_bus_energy_J"], rel=1e-9)
        split = effects["mismatch_split"]["optimal"]
        assert split["predicted_J"] == pytest.approx(planned["optimal"]["net_electrical_energy_J"], rel=1e-12)
        assert split["predicted_at_true_masses_J"] > split["predicted_J"]
        replanned = effects["mismatch_replanned"]  # the mix solved again once at the true masses
        assert replanned["task"] == effects["task"] == planned["name"]
        assert replanned["lengths"] == real["tasks"][0]["plant_effects"]["mismatch_replanned"]["lengths"]  # one design
        assert split["replanned_optimum_predicted_J"] == replanned["predicted_J"] > split["predicted_J"]
        weighted["replanned"] += planned["weight"] * replanned["predicted_J"]
        weighted["nominal at true masses"] += planned["weight"] * split["predicted_at_true_masses_J"]
        words = f"(one solve for all its tasks) predicts {replanned['predicted_J']:.1f} J on this task"
        assert words in (tmp_path / "real" / f"effects_task{k}.md").read_text(encoding="utf-8")
        title = (tmp_path / "real" / f"effects_task{k}.md").read_text(encoding="utf-8").splitlines()[0]
        assert f"task {planned['name']} (its own plans and energies)" in title
    assert not (tmp_path / "real" / "effects.md").exists()
    # The re-planned mix is no worse, weighted over its tasks, than the nominal optimum at the true masses
    # (within the small study's solver and ID tolerances, as for a single task).
    assert weighted["replanned"] <= weighted["nominal at true masses"] * (1 + 1e-3)

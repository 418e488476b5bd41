"""``hiab-sim optimize`` end to end on a small, fast study: results, tracking, bad input, resume."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from test_study_small import small_study, write_study

from hiab_sim.cli import main

FLAGS = ["--no-video", "--quiet", "--no-figures"]


@pytest.fixture(scope="module")
def solved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small study optimised once (analytic ID path), with its figures."""
    folder = tmp_path_factory.mktemp("small")
    study = write_study(folder, small_study())
    assert main(["optimize", str(study), "--out", str(folder / "out"), "--no-video", "--quiet"]) == 0
    return folder / "out"


def test_optimum_is_feasible_better_and_reported(solved: Path) -> None:
    """Success, max violation <= 1e-6, lower energy, the renderer's keys, and the figures."""
    r = json.loads((solved / "result.json").read_text())
    assert r["crane"] == "xs031"
    assert r["solver"]["success"] and r["solver"]["max_violation_scaled"] <= 1e-6
    assert r["optimal"]["net_electrical_energy_J"] < r["initial"]["net_electrical_energy_J"]
    assert r["optimal"]["collocation_cost_W2s"] < r["initial"]["collocation_cost_W2s"]
    for design in ("initial", "optimal"):
        assert set(r[design]["lengths"]) == {"lift", "tilt"}
        assert set(r[design]["lengths"]["lift"]) == {"L", "Lc0", "Lc"}
    assert len(list(solved.glob("*.png"))) == 8


def test_tracking_holds_on_the_fine_grid_with_the_other_id_path(solved: Path) -> None:
    """Re-check on the 10x finer grid: every constraint, tracking within the band, TCP on the spiral."""
    r = json.loads((solved / "result.json").read_text())
    rc = r["recheck"]
    assert rc["id_path"] == "mujoco" and rc["grid_points"] == 121
    assert rc["max_violation_scaled"] <= 1e-6
    assert rc["tracking_error"]["position_m"] <= 2e-3
    data = np.load(solved / "trajectory.npz")
    assert data["time"].shape == (121,)
    assert data["optimal_position"].shape == data["reference_tcp"].shape == (121, 3)
    err = np.abs(data["optimal_tcp"][:, :2] - data["reference_tcp"][:, :2])
    assert err.max() <= 2e-3


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"reference": {**small_study()["reference"], "end_radius": 5.0}}, "reference"),
        (
            {
                "initial_lengths": {
                    "lift": {"L": 1.0071227324212, "Lc0": 0.2, "Lc": 0.745},
                    "tilt": {"L": 1.132185817991, "Lc0": 0.085, "Lc": 0.745},
                }
            },
            "initial_lengths",
        ),
        ({"spline": {"control_points": "many"}}, "spline.control_points"),
    ],
)
def test_bad_input_exits_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], change: dict, needle: str
) -> None:
    """Unreachable reference, infeasible start, malformed study: named error, exit 2, no output folder."""
    study = write_study(tmp_path, small_study(**change))
    out = tmp_path / "out"
    assert main(["optimize", str(study), "--out", str(out), *FLAGS]) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_invalid_yaml_exits_2(tmp_path: Path) -> None:
    """A study that is not YAML is a named error, exit 2."""
    bad = tmp_path / "bad.yaml"
    bad.write_text("crane: [unclosed\n")
    assert main(["optimize", str(bad), "--out", str(tmp_path / "o"), *FLAGS]) == 2


def test_solver_failure_keeps_history_and_resume_continues(tmp_path: Path) -> None:
    """An iteration limit exits 1 with the checkpoint kept; --resume continues from its last iterate."""
    study = small_study(solver={"maxiter": 3, "ftol": 1e-9, "id_path": "analytic"})
    path = write_study(tmp_path, study)
    out = tmp_path / "out"
    assert main(["optimize", str(path), "--out", str(out), *FLAGS]) == 1
    first = json.loads((out / "checkpoint_0.json").read_text())
    assert not first["done"] and len(first["history"]) >= 3
    assert not (out / "result.json").exists()
    path = write_study(tmp_path, small_study())
    assert main(["optimize", str(path), "--out", str(out), "--resume", *FLAGS]) == 0
    r = json.loads((out / "result.json").read_text())
    assert r["history"][: len(first["history"])] == first["history"]
    assert r["solver"]["success"]

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
    """Re-check on the 10x finer grid: every constraint, tracking within the band, TCP on the spiral.

    The small study's position band is 2 mm, held as 1 mm (collocation_fraction 0.5) at the
    collocation points (every 10th fine point): the TCP error must stay within 2 mm everywhere and
    within 1 mm (+1 % for round-off) at the collocation points.
    """
    tracking = small_study()["tracking"]
    band = tracking["position"]
    held = band * tracking["collocation_fraction"]
    assert (band, held) == (2e-3, 1e-3)
    r = json.loads((solved / "result.json").read_text())
    rc = r["recheck"]
    assert rc["id_path"] == "mujoco" and rc["grid_points"] == 121
    assert rc["max_violation_scaled"] <= 1e-6
    assert rc["tracking_error"]["position_m"] <= band
    data = np.load(solved / "trajectory.npz")
    assert data["time"].shape == (121,)
    assert data["optimal_position"].shape == data["reference_tcp"].shape == (121, 3)
    err = np.abs(data["optimal_tcp"][:, :2] - data["reference_tcp"][:, :2])
    assert err.max() <= band
    np.testing.assert_allclose(data["time"][::10], np.linspace(0.0, 6.25, 13), atol=1e-12)
    assert err[::10].max() <= 1.01 * held


def test_energy_decomposition_is_consistent(solved: Path) -> None:
    """The four (lengths, trajectory) combinations: the pure ones are the initial and optimal designs."""
    r = json.loads((solved / "result.json").read_text())
    d = r["improvement"]["decomposition"]
    designs = d["designs"]
    e = {k: v["net_electrical_energy_J"] for k, v in designs.items()}
    ini, opt = r["initial"], r["optimal"]
    assert e["initial_lengths_initial_trajectory"] == pytest.approx(ini["net_electrical_energy_J"], rel=1e-12)
    assert e["optimal_lengths_optimal_trajectory"] == pytest.approx(opt["net_electrical_energy_J"], rel=1e-12)
    for key, design in (("initial_lengths_initial_trajectory", ini), ("optimal_lengths_optimal_trajectory", opt)):
        assert designs[key]["cost_W2s"] == pytest.approx(design["cost_W2s"], rel=1e-12)
        assert designs[key]["collocation_cost_W2s"] == pytest.approx(design["collocation_cost_W2s"], rel=1e-12)
        assert designs[key]["max_violation"] == pytest.approx(design["max_violation"], rel=1e-9, abs=1e-15)
    # the mixed designs really mix: their energies differ from both pure designs
    for key in ("optimal_lengths_initial_trajectory", "initial_lengths_optimal_trajectory"):
        assert designs[key]["evaluable"] and designs[key]["max_violation"] >= 0.0
        assert e[key] not in (e["initial_lengths_initial_trajectory"], e["optimal_lengths_optimal_trajectory"])
    e00 = e["initial_lengths_initial_trajectory"]
    assert d["from_lengths_J"] == pytest.approx(e00 - e["optimal_lengths_initial_trajectory"], rel=1e-12)
    assert d["from_trajectory_J"] == pytest.approx(e00 - e["initial_lengths_optimal_trajectory"], rel=1e-12)
    assert d["from_lengths_percent"] == pytest.approx(100.0 * d["from_lengths_J"] / e00, rel=1e-12)
    total = d["from_lengths_J"] + d["from_trajectory_J"] + d["interaction_J"]
    assert total == pytest.approx(r["improvement"]["net_energy_saved_J"], rel=1e-9)
    assert d["total_J"] == pytest.approx(r["improvement"]["net_energy_saved_J"], rel=1e-12)


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
        (
            {
                "initial_lengths": {
                    "lift": {"L": 1.0071227324212, "Lc0": 0.08501, "Lc": 0.745},
                    "tilt": {"L": 1.132185817991, "Lc0": 0.085, "Lc": 0.745},
                }
            },
            "working_range.lift.x >= 0 at the low end",
        ),
        ({"spline": {"control_points": "many"}}, "spline.control_points"),
    ],
)
def test_bad_input_exits_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], change: dict, needle: str
) -> None:
    """Unreachable reference, infeasible start, malformed study: named error, exit 2, no output folder.

    The infeasible starts: lift Lc0 0.2 m (by far) and 0.08501 m (stroke -1e-5 m = -1e-4 scaled).
    """
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


def test_checkpoint_records_its_run_and_resume_refuses_another(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--resume with a checkpoint of another study (content or path), ID path or start: named field, exit 2."""
    limited = small_study(solver={"maxiter": 3, "ftol": 1e-9, "id_path": "analytic"})
    path = write_study(tmp_path, limited)
    out = tmp_path / "out"
    assert main(["optimize", str(path), "--out", str(out), *FLAGS]) == 1
    checkpoint = out / "checkpoint_0.json"
    text = checkpoint.read_text()
    data = json.loads(text)
    assert data["study"] == str(path.resolve()) and data["id_path"] == "analytic"
    assert len(data["study_sha256"]) == 64
    assert data["initial_xi"] == [1.0071227324212, 0.085, 0.745, 1.132185817991, 0.085, 0.745]
    other_content = small_study(tracking={**small_study()["tracking"], "position": 3e-3})
    edited = dict(data, initial_xi=[1.0, *data["initial_xi"][1:]])
    cases = [  # (field that differs, study content, study file name, extra flags, checkpoint text)
        ("study_sha256", other_content, "study.yaml", [], text),
        ("study", limited, "copy.yaml", [], text),
        ("id_path", limited, "study.yaml", ["--id", "mujoco"], text),
        ("initial_xi", limited, "study.yaml", [], json.dumps(edited)),
    ]
    for field, content, name, extra, checkpoint_text in cases:
        study = write_study(tmp_path, content, name)
        checkpoint.write_text(checkpoint_text)
        capsys.readouterr()
        assert main(["optimize", str(study), "--out", str(out), "--resume", *extra, *FLAGS]) == 2, field
        err = capsys.readouterr().err
        assert f"--resume (checkpoint_0.json {field})" in err and len(err.strip().splitlines()) == 1, err
        assert checkpoint.read_text() == checkpoint_text
        assert not (out / "result.json").exists()


def test_fresh_run_removes_checkpoints_of_earlier_runs(tmp_path: Path) -> None:
    """Without --resume, old checkpoint_*.json files go before the new ones are written."""
    out = tmp_path / "out"
    out.mkdir()
    stale = out / "checkpoint_1.json"
    stale.write_text(json.dumps({"history": [], "done": True}))
    (out / "checkpoint_0.json").write_text(json.dumps({"history": [], "done": True}))
    path = write_study(tmp_path, small_study(solver={"maxiter": 2, "ftol": 1e-9, "id_path": "analytic"}))
    assert main(["optimize", str(path), "--out", str(out), *FLAGS]) == 1
    assert not stale.exists()
    data = json.loads((out / "checkpoint_0.json").read_text())
    assert not data["done"] and data["study"] == str(path.resolve()) and len(data["history"]) >= 2


def test_failed_start_is_listed_not_grouped_as_an_optimum(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A start stopped by its iteration limit is under failed_starts, in no distinct optimum."""
    from hiab_sim.study import run as run_module

    real_solve = run_module.solve

    def solve(problem, initial, start=0, **kwargs):  # type: ignore[no-untyped-def]
        if start == 1:
            kwargs["maxiter"] = 1
        return real_solve(problem, initial, start=start, **kwargs)

    monkeypatch.setattr(run_module, "solve", solve)
    path = write_study(tmp_path, small_study())
    out = tmp_path / "out"
    assert main(["optimize", str(path), "--out", str(out), "--starts", "2", *FLAGS]) == 0
    ms = json.loads((out / "result.json").read_text())["multistart"]
    assert [f["start"] for f in ms["failed_starts"]] == [1]
    assert "Iteration limit" in ms["failed_starts"][0]["message"]
    assert ms["converged_starts"] == 1
    assert [d["starts"] for d in ms["distinct_optima"]] == [[0]]
    row = ms["starts"][1]
    assert row["success"] is False and row["optimal_lengths"] is None and row["cost_W2s"] is None
    printed = capsys.readouterr().out
    assert "all 1 converged starts" in printed and "start 1 failed (not an optimum)" in printed

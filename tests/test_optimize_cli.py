"""``hiab-sim optimize`` end to end on a small, fast study: results, tracking, bad input, resume."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from result_checks import four_designs
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.emla import load_emla_set
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import SCHEMA_VERSION
from hiab_sim.study.spec.study_file import study_from_dict

#: End-to-end runs of whole studies and commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e

FLAGS = ["--no-video", "--quiet", "--no-figures"]


@pytest.fixture(scope="module")
def solved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small study optimised once (analytic ID path), with its figures."""
    folder = tmp_path_factory.mktemp("small")
    study = write_study(folder, small_study())
    assert main(["optimize", str(study), "--out", str(folder / "out"), "--no-video", "--quiet"]) == 0
    return folder / "out"


def _key_paths(data: object, prefix: str = "") -> set[str]:
    """Dotted key paths of a JSON value; list items as ``[]``."""
    if isinstance(data, dict):
        out = set()
        for key, value in data.items():
            path = f"{prefix}.{key}" if prefix else key
            out |= {path} | _key_paths(value, path)
        return out
    if isinstance(data, list):
        return set().union(*(_key_paths(v, prefix + "[]") for v in data)) if data else set()
    return set()


def test_optimum_is_feasible_better_and_reported(solved: Path) -> None:
    """Success, max violation <= 1e-6, lower energy, the renderer's keys, and the figures."""
    r = read_result(solved)
    assert r.crane == "xs031" and r.schema_version == SCHEMA_VERSION == 2
    assert r.solver.success and r.solver.max_violation_scaled <= 1e-6
    assert r.optimal.net_electrical_energy_J < r.initial.net_electrical_energy_J
    assert r.optimal.collocation_cost_W2s is not None and r.initial.collocation_cost_W2s is not None
    assert r.optimal.collocation_cost_W2s < r.initial.collocation_cost_W2s
    raw = json.loads((solved / "result.json").read_text())
    for design in ("initial", "optimal"):
        assert set(raw[design]["lengths"]) == {"lift", "tilt"}
        assert set(raw[design]["lengths"]["lift"]) == {"L", "Lc0", "Lc"}
    # 8 + energy_emla_vs_hydraulic.png + sensitivity.png + structure_natural_frequency.png
    assert len(list(solved.glob("*.png"))) == 11
    assert (solved / "sensitivity.png").is_file() and (solved / "structure_natural_frequency.png").is_file()


def test_result_json_keeps_every_key_of_schema_1_and_round_trips(solved: Path) -> None:
    """Every key path written before the result was typed is still written; file -> Result -> JSON is exact."""
    raw = json.loads((solved / "result.json").read_text())
    lines = (Path(__file__).parent / "data" / "result_keys_schema1.txt").read_text().splitlines()
    contract = {line for line in lines if line and not line.startswith("#")}
    assert len(contract) > 250
    assert contract - _key_paths(raw) == set()
    assert read_result(solved).to_json() == raw
    assert next(iter(raw)) == "schema_version"


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
    rc = read_result(solved).recheck
    assert rc.id_path == "mujoco" and rc.grid_points == 121
    assert rc.max_violation_scaled <= 1e-6
    assert rc.tracking_error.position_m <= band
    data = np.load(solved / "trajectory.npz")
    assert data["time"].shape == (121,)
    assert data["optimal_position"].shape == data["reference_tcp"].shape == (121, 3)
    err = np.abs(data["optimal_tcp"][:, :2] - data["reference_tcp"][:, :2])
    assert err.max() <= band
    np.testing.assert_allclose(data["time"][::10], np.linspace(0.0, 6.25, 13), atol=1e-12)
    assert err[::10].max() <= 1.01 * held


def test_designs_and_decomposition_match_an_independent_evaluation(solved: Path) -> None:
    """Re-evaluated by the other ID path, the four designs' energies and the interaction E10 + E01 - E00 - E11 agree.

    The report evaluates each design through the problem on the analytic path; here the lengths of
    result.json and the joint samples of trajectory.npz go through the MuJoCo ID, the EMLA power and
    the quadratures of tests/result_checks.py. The paths agree to ~1e-14 in force, so energies agree to
    1e-9 relative and the interaction (a difference of ~3.6 kJ energies) to 1e-6 J.
    """
    r = read_result(solved)
    study = study_from_dict(small_study(), "small.yaml")
    e = four_designs(solved, r, study.crane, load_emla_set())
    d = r.improvement.decomposition
    for (xi, trajectory), (net, cost) in e.items():
        design = d.designs[f"{xi}_lengths_{trajectory}_trajectory"]
        assert design.evaluable
        assert design.net_electrical_energy_J == pytest.approx(net, rel=1e-9)
        assert design.cost_W2s == pytest.approx(cost, rel=1e-9)
    for name, summary in (("initial", r.initial), ("optimal", r.optimal)):
        assert summary.net_electrical_energy_J == pytest.approx(e[name, name][0], rel=1e-9)
        assert summary.cost_W2s == pytest.approx(e[name, name][1], rel=1e-9)
    e00, e10, e01, e11 = (
        e[k][0] for k in (("initial",) * 2, ("optimal", "initial"), ("initial", "optimal"), ("optimal",) * 2)
    )
    # the mixed designs really mix: their energies differ from both pure designs by more than round-off
    assert min(abs(e10 - e00), abs(e10 - e11), abs(e01 - e00), abs(e01 - e11)) > 1e-3
    assert d.from_lengths_J == pytest.approx(e00 - e10, abs=1e-6)
    assert d.from_trajectory_J == pytest.approx(e00 - e01, abs=1e-6)
    assert d.total_J == pytest.approx(e00 - e11, abs=1e-6)
    assert r.improvement.net_energy_saved_J == pytest.approx(e00 - e11, abs=1e-6)
    assert d.from_lengths_percent == pytest.approx(100.0 * (e00 - e10) / e00, rel=1e-6)


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
    assert main(["optimize", str(path), "--out", str(out), "--starts", "2", *FLAGS, "--verbose"]) == 0
    raw = json.loads((out / "result.json").read_text())["multistart"]
    assert set(raw["failed_starts"][0]) == {"start", "initial_xi", "message"}
    assert set(raw["distinct_optima"][0]) == {"xi", "cost_W2s", "starts", "net_electrical_energy_J", "objective_value"}
    assert (raw["objective"], raw["objective_unit"]) == ("costf2", "W^2 s")
    assert raw["starts"][1]["optimal_lengths"] is None and raw["starts"][1]["cost_W2s"] is None
    ms = read_result(out).multistart
    assert [f.start for f in ms.failed_starts] == [1]
    assert "Iteration limit" in ms.failed_starts[0].message
    assert ms.converged_starts == 1
    assert [d.starts for d in ms.distinct_optima] == [(0,)]
    # the optimum's objective is the result's own: costf2 on the fine grid at start 0's design
    assert ms.distinct_optima[0].objective_value == pytest.approx(read_result(out).optimal.cost_W2s, rel=1e-12)
    row = ms.starts[1]
    assert row.success is False and row.optimal_lengths is None and row.cost_W2s is None
    printed = capsys.readouterr().out
    assert "all 1 converged starts" in printed and "start 1 failed (not an optimum)" in printed
    assert "Starts: 1 of 2 converged" in printed and "1 failed." in printed  # the summary says it too


def test_study_whose_drives_lack_stiffness_data_writes_every_figure_but_the_frequencies(tmp_path: Path) -> None:
    """seed_scale_spiral's EMLA file has no screw or drive-stiffness data: no frequencies, and the run still ends."""
    root = Path(__file__).resolve().parents[1]
    out = tmp_path / "seed"
    assert main(["optimize", str(root / "optimize" / "seed_scale_spiral.yaml"), "--out", str(out), *FLAGS[:2]]) == 0
    r = read_result(out)
    assert r.structure is not None and r.structure.optimal.lowest_frequency_working_range_Hz is None
    assert (out / "structure_initial_vs_optimal.png").is_file()
    assert not (out / "structure_natural_frequency.png").exists()

"""Sweeps: bad sweep files, local processes vs a Dask LocalCluster, resume after an interruption."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd
import pytest
import yaml
from test_study_small import TINY, machine_form, small_study, write_study

from hiab_sim.cli import main
from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.sweep.executors import make_executor
from hiab_sim.sweep.point import TIMING_COLUMNS
from hiab_sim.sweep.runner import run_sweep
from hiab_sim.sweep.spec import load_sweep
from hiab_sim.sweep.table import read_table

#: End-to-end runs of whole studies and commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e

GRID = {"payload": [0.0, 150.0], "emla.lift.gear_ratio": [4.0, 5.0]}


def write_sweep(folder: Path, body: dict[str, Any], name: str = "sweep.yaml") -> Path:
    """Write the tiny study and a sweep file over it; return the sweep file."""
    write_study(folder, small_study(**TINY))
    path = folder / name
    path.write_text(yaml.safe_dump({"study": "study.yaml", **body}, sort_keys=False))
    return path


def comparable(frame: pd.DataFrame) -> pd.DataFrame:
    """The table without its timing columns (they differ between runs of the same point).

    The name of the worst constraint is left out too: at an optimum two rows often tie to round-off
    (both chains' working-range rows at the same clearance), and which one is named then depends on the
    last bit; its margin (``smallest_margin``) stays in.
    """
    return frame.drop(columns=[*TIMING_COLUMNS, "worst_constraint"]).reset_index(drop=True)


def assert_same_table(a: pd.DataFrame, b: pd.DataFrame) -> None:
    """Two sweep tables agree: same keys, parameters, statuses, and numbers to 1e-7 relative."""
    pd.testing.assert_frame_equal(comparable(a), comparable(b), check_exact=False, rtol=1e-7, atol=1e-12)


@pytest.fixture(scope="module")
def local_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, pd.DataFrame]:
    """The 4-point sweep on 2 local processes, uninterrupted, through the CLI."""
    folder = tmp_path_factory.mktemp("sweep")
    path = write_sweep(folder, {"grid": GRID})
    assert main(["sweep", str(path), "--workers", "2", "--out", str(folder / "local"), "--quiet"]) == 0
    assert (folder / "local" / "sweep_summary.png").is_file() and (folder / "local" / "sweep_saving_map.png").is_file()
    frame, _ = read_table(folder / "local" / "sweep.parquet")
    for key in frame["key"]:
        assert (folder / "local" / "points" / key / "result.json").is_file()
    return path, frame


def test_sweep_table_has_a_row_per_point_with_energies(local_run: tuple[Path, pd.DataFrame]) -> None:
    """Every grid point is optimised: parameters as given, energies positive, the optimum no worse than the start."""
    _, frame = local_run
    assert len(frame) == 4 and (frame["status"] == "ok").all()
    assert sorted(zip(frame["payload"], frame["emla.lift.gear_ratio"], strict=True)) == [
        (0.0, 4.0),
        (0.0, 5.0),
        (150.0, 4.0),
        (150.0, 5.0),
    ]
    assert (frame["opt_cost_W2s"] <= frame["start_cost_W2s"]).all()
    assert (frame["opt_net_energy_J"] > 0).all() and (frame["iterations"] > 0).all()
    # a heavier payload costs more energy at the same gear ratio
    by = frame.set_index(["emla.lift.gear_ratio", "payload"])["start_net_energy_J"]
    assert by[(4.0, 150.0)] > by[(4.0, 0.0)] and by[(5.0, 150.0)] > by[(5.0, 0.0)]


def test_dask_cluster_gives_the_local_table(local_run: tuple[Path, pd.DataFrame], tmp_path: Path) -> None:
    """The same sweep on a Dask LocalCluster (2 worker processes) gives the same table as on local processes."""
    distributed = pytest.importorskip("distributed")
    path, local = local_run
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with make_executor(dask=cluster.scheduler_address) as executor:
            outcome = run_sweep(load_sweep(path), tmp_path / "dask", executor, progress=False)
    frame, _ = read_table(outcome.table)
    assert_same_table(frame, local)


class StopSweepError(Exception):
    """Raised by the test hook to interrupt a sweep."""


def test_resume_after_interruption_runs_each_point_once(local_run: tuple[Path, pd.DataFrame], tmp_path: Path) -> None:
    """A sweep stopped after 2 points and resumed gives the uninterrupted table; no finished point runs again."""
    path, reference = local_run
    sweep = load_sweep(path)
    seen: list[str] = []

    def stop_after_two(row: dict[str, Any]) -> None:
        seen.append(row["key"])
        if len(seen) == 2:
            raise StopSweepError

    with make_executor(workers=1) as executor, pytest.raises(StopSweepError):
        run_sweep(sweep, tmp_path, executor, progress=False, on_row=stop_after_two)
    partial, _ = read_table(tmp_path / "sweep.parquet")
    assert sorted(partial["key"]) == sorted(seen)
    with make_executor(workers=1) as executor:
        outcome = run_sweep(sweep, tmp_path, executor, resume=True, progress=False)
    assert sorted(outcome.skipped) == sorted(seen)
    assert sorted(outcome.ran) == sorted(set(p.key for p in sweep.points) - set(seen))
    final, _ = read_table(outcome.table)
    assert_same_table(final, reference)
    # the finished rows were kept as they were, timing included
    kept = final.set_index("key").loc[partial["key"], "wall_time_s"].to_numpy()
    assert (kept == partial["wall_time_s"].to_numpy()).all()


def test_resume_refuses_a_table_of_another_sweep(local_run: tuple[Path, pd.DataFrame], tmp_path: Path) -> None:
    """--resume on a table written by another sweep file fails naming --resume, before any point runs."""
    path, _ = local_run
    other = write_sweep(tmp_path, {"grid": {"payload": [0.0, 50.0]}}, "other.yaml")
    table = path.parent / "local"
    with make_executor(workers=1) as executor, pytest.raises(InvalidInputError, match="--resume"):
        run_sweep(load_sweep(other), table, executor, resume=True, progress=False)


def test_a_failed_point_is_recorded_and_the_sweep_goes_on(tmp_path: Path) -> None:
    """A point whose start is infeasible (lift Lc0 too long for the stroke) is a failed row with its message."""
    path = write_sweep(tmp_path, {"grid": {"initial_lengths.lift.Lc0": [0.085, 0.25]}, "set": _initial()})
    with make_executor(workers=2) as executor:
        outcome = run_sweep(load_sweep(path), tmp_path / "out", executor, progress=False)
    frame, _ = read_table(outcome.table)
    status = dict(zip(frame["initial_lengths.lift.Lc0"], frame["status"], strict=True))
    assert status == {0.085: "ok", 0.25: "failed"}
    assert "initial_lengths" in frame.loc[frame["status"] == "failed", "message"].iloc[0]
    assert len(outcome.failed) == 1


def _initial() -> dict[str, Any]:
    """The XS 031 lengths written out, so that one of them can be swept."""
    lengths = load_crane("xs031").default_lengths
    return {
        "initial_lengths": {
            name: {k: float(getattr(getattr(lengths, name), k)) for k in ("L", "Lc0", "Lc")}
            for name in ("lift", "tilt")
        }
    }


@pytest.mark.parametrize(
    ("body", "named"),
    [
        ({"grid": {"bounds.lift.upp": [1.0]}}, "bounds.lift.upp"),
        ({"grid": {"payload": []}}, "grid.payload"),
        ({"grid": {"payload": [-5.0]}}, "payload"),
        ({"grid": {"bounds.lift.up[7]": [1.0]}}, "bounds.lift.up[7]"),
        ({"grid": {"emla.lift.gear_ratioo": [4.0]}}, "emla.lift.gear_ratioo"),
        ({"grid": {"emla.lift.gear_ratio": [-1.0]}}, "emla.lift.gear_ratio"),
        ({"sample": {"points": 3, "seed": 1, "ranges": {"payload": [10.0, 5.0]}}}, "sample.ranges.payload"),
    ],
)
def test_bad_sweep_file_exits_2_naming_the_path(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], body: dict[str, Any], named: str
) -> None:
    """Unknown path, empty grid, a rejected value: one line naming the path, exit 2, nothing run."""
    path = write_sweep(tmp_path, body)
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and named in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_latin_hypercube_sample_is_seeded_and_stratified(tmp_path: Path) -> None:
    """The LHS points lie in their ranges, one per stratum of each axis, and repeat with the same seed."""
    body = {"sample": {"points": 8, "seed": 3, "ranges": {"payload": [0.0, 400.0], "emla.tilt.gear_ratio": [3, 7]}}}
    a, b = load_sweep(write_sweep(tmp_path, body)), load_sweep(write_sweep(tmp_path, body, "again.yaml"))
    assert [p.values for p in a.points] == [p.values for p in b.points]
    for column, (lo, hi) in body["sample"]["ranges"].items():  # type: ignore[index]
        values = sorted(p.values[column] for p in a.points)
        strata = [int((v - lo) / (hi - lo) * 8) for v in values]
        assert strata == list(range(8))
    assert a.points[0].emla is not None
    assert a.points[0].emla["actuators"]["tilt"]["gear_ratio"]["value"] == a.points[0].values["emla.tilt.gear_ratio"]


def test_zipped_axis_moves_its_paths_together(tmp_path: Path) -> None:
    """A zipped grid axis sets all its paths from the same index; its 'values' become a column."""
    axis = {"values": [0, 10], "bounds.lift.up[0]": [1.1, 1.2], "bounds.tilt.up[0]": [1.2, 1.3]}
    sweep = load_sweep(write_sweep(tmp_path, {"grid": {"opening": axis, "payload": [0.0, 10.0]}}))
    assert sweep.columns == ("opening", "bounds.lift.up[0]", "bounds.tilt.up[0]", "payload")
    assert sweep.axes == ("opening", "payload")
    assert len(sweep.points) == 4
    for p in sweep.points:
        k = axis["values"].index(p.values["opening"])
        assert p.study["bounds"]["lift"]["up"][0] == axis["bounds.lift.up[0]"][k]
        assert p.study["bounds"]["tilt"]["up"][0] == axis["bounds.tilt.up[0]"][k]


def test_shipped_study_name_resolves(tmp_path: Path) -> None:
    """``study: xs031_spiral`` names the shipped study when no such file sits next to the sweep file."""
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({"study": "xs031_spiral", "grid": {"payload": [0.0]}}))
    assert load_sweep(path).study_file.name == "xs031_spiral.yaml"
    path.write_text(yaml.safe_dump({"study": "no_such_study", "grid": {"payload": [0.0]}}))
    with pytest.raises(ConfigError, match="no_such_study"):
        load_sweep(path)


def test_sweep_of_a_machine_files_study_names_its_variables_and_actuators(tmp_path: Path) -> None:
    """A sweep over the eXact arm's digging study: EMLA paths by the file's actuators, columns by its variables."""
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({"study": "exact_digging", "grid": {"emla.boom.gear_ratio": [3.5, 4.5]}}))
    sweep = load_sweep(path)
    assert sweep.design_names[:3] == ("boom.L", "boom.Lc0", "boom.Lc") and "bucket.Gx" in sweep.design_names
    ratios = [p.emla["actuators"]["boom"]["gear_ratio"]["value"] for p in sweep.points if p.emla is not None]
    assert ratios == [3.5, 4.5]
    path.write_text(yaml.safe_dump({"study": "exact_digging", "grid": {"emla.lift.gear_ratio": [4.0]}}))
    with pytest.raises(ConfigError, match=r"emla\.lift\.gear_ratio"):
        load_sweep(path)


def test_machine_file_sweep_point_is_the_crane_file_sweep_point(tmp_path: Path) -> None:
    """One point of the tiny study through the XS 031's machine file gives the crane file's optimum and energies."""
    crane = small_study(**TINY)
    machine = machine_form(crane)
    frames = {}
    for key, study in (("crane", crane), ("machine", machine)):
        folder = tmp_path / key
        folder.mkdir()
        write_study(folder, study)
        path = folder / "sweep.yaml"
        path.write_text(yaml.safe_dump({"study": "study.yaml", "grid": {"payload": [60.0]}}))
        with make_executor(workers=1) as executor:
            outcome = run_sweep(load_sweep(path), folder / "out", executor, progress=False)
        frames[key], _ = read_table(outcome.table)
    a, b = frames["crane"].iloc[0], frames["machine"].iloc[0]
    assert a["status"] == b["status"] == "ok", (a["message"], b["message"])
    columns = [c for c in frames["crane"].columns if c.startswith("opt_") or c.startswith("start_")]
    assert "opt_lift_L_m" in columns and "opt_tilt_Lc_m" in columns
    for c in columns:
        assert b[c] == pytest.approx(a[c], rel=1e-6, abs=1e-7), c

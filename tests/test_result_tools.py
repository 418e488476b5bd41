"""Tools on result folders: ``mjcf --from-result`` exports the exact design, ``compare`` tables and figures."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import mujoco
import numpy as np
import pytest

from hiab_sim.cli import main
from hiab_sim.crane.loader import load_crane

#: End-to-end runs of whole studies and commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e

CRANE = load_crane("xs031")


def _xi(result: dict, design: str) -> np.ndarray:
    chains = result[design]["lengths"]
    return np.array([chains[c][k] for c in ("lift", "tilt") for k in ("L", "Lc0", "Lc")])


@pytest.mark.parametrize("design", ["optimal", "initial"])
def test_mjcf_from_result_places_the_exact_design(small_run: Path, tmp_path: Path, design: str) -> None:
    """The exported model's base pivots, rod bodies and rod-end sites are the result's lengths to 1e-15 m."""
    out = tmp_path / f"{design}.xml"
    assert main(["mjcf", "--from-result", str(small_run), "--design", design, "-o", str(out)]) == 0
    xi = _xi(json.loads((small_run / "result.json").read_text()), design)
    model = mujoco.MjModel.from_xml_path(str(out))
    for k, chain in enumerate(CRANE.chains):
        L, Lc0, Lc = xi[3 * k : 3 * k + 3]
        pivot = chain.boom_hinge - L * chain.base_axis
        np.testing.assert_allclose(model.body(f"{chain.name}_cylinder").pos, pivot, atol=1e-15)
        x_home = model.qpos0[model.joint(f"x{k + 1}").qposadr[0]]  # bodies are placed at home (joint ref)
        assert model.body(f"{chain.name}_rod").pos[0] - x_home == pytest.approx(Lc0, rel=1e-15, abs=1e-15)
        assert model.site(f"{chain.name}_rod_end").pos[0] == Lc


def test_mjcf_from_result_rejects_a_missing_folder_and_mixed_options(small_run: Path, tmp_path: Path, capsys) -> None:
    """A missing folder, a folder without result.json, --lengths or --crane with --from-result: exit 2, one line."""
    for argv in (
        ["mjcf", "--from-result", str(tmp_path / "nope")],
        ["mjcf", "--from-result", str(tmp_path)],
        ["mjcf", "--from-result", str(small_run), "--lengths", "1,0.1,0.7,1.1,0.1,0.7"],
        ["mjcf", "--from-result", str(small_run), "--crane", "xs031"],  # the result names its crane
    ):
        assert main([*argv, "-o", str(tmp_path / "x.xml")]) == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
    assert not (tmp_path / "x.xml").exists()


def test_compare_table_matches_each_result(small_run: Path, tmp_path: Path, capsys) -> None:
    """Compare writes one CSV row per run and design whose lengths, energies and savings are the results' own."""
    second = tmp_path / "copy"
    shutil.copytree(small_run, second)
    data = json.loads((second / "result.json").read_text())
    data["name"] = "copy"
    (second / "result.json").write_text(json.dumps(data))
    out = tmp_path / "cmp"
    assert main(["compare", str(small_run), str(second), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "saving [%]" in printed and "copy: copy, objective costf2" in printed
    assert max(len(line) for line in printed.splitlines() if not line.startswith("wrote")) <= 100
    with (out / "comparison.csv").open() as handle:
        table = list(csv.DictReader(handle))
    assert [(r["run"], r["design"]) for r in table] == [
        ("out", "initial"), ("out", "optimal"), ("copy", "initial"), ("copy", "optimal")
    ]  # fmt: skip
    result = json.loads((small_run / "result.json").read_text())
    for row in table[:2]:
        lengths = [float(row[f"{c} {k} [mm]"]) for c in ("lift", "tilt") for k in ("L", "Lc0", "Lc")]
        np.testing.assert_allclose(lengths, 1e3 * _xi(result, row["design"]), rtol=1e-15)
        energy = result[row["design"]]["net_electrical_energy_J"]
        assert float(row["net electrical energy at the drives [kJ]"]) == pytest.approx(energy / 1e3, rel=1e-15)
    saved = float(table[1]["net electrical energy saving vs initial [%]"])
    assert saved == pytest.approx(result["improvement"]["net_energy_saved_percent"], rel=1e-9)
    assert (out / "comparison.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_compare_without_out_writes_nothing_and_fits_100_columns(
    small_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without --out, compare only prints (no ./comparison/); the table's rows fit 100 columns, a long name is whole."""
    second = tmp_path / ("a_rather_long_run_folder_name_" * 4)
    shutil.copytree(small_run, second)
    data = json.loads((second / "result.json").read_text())
    data["name"] = second.name
    (second / "result.json").write_text(json.dumps(data))
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    assert main(["compare", str(small_run), str(second)]) == 0
    printed = capsys.readouterr().out
    assert max(len(line) for line in printed.splitlines() if not line.startswith(second.name)) <= 100
    assert f"{second.name}: {second.name}, objective costf2" in printed  # its own line, whole
    assert list(work.iterdir()) == []


def test_compare_saving_is_of_the_objectives_energy_and_labels_runs_by_folder(
    small_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two folders of one study named ``run`` read ``a/run`` and ``b/run``; each saving is of its objective's energy.

    With the objective ``battery_energy`` the saving is the battery energy's that ``optimize`` wrote
    (``energy.battery_energy_saved_percent``), with ``costf2`` the net electrical energy's.
    """
    result = json.loads((small_run / "result.json").read_text())
    for parent, objective in (("a", "costf2"), ("b", "battery_energy")):
        folder = tmp_path / parent / "run"
        shutil.copytree(small_run, folder)
        data = json.loads((folder / "result.json").read_text())
        data["energy"]["objective"] = objective
        (folder / "result.json").write_text(json.dumps(data))
    out = tmp_path / "cmp"
    assert main(["compare", str(tmp_path / "a" / "run"), str(tmp_path / "b" / "run"), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "a/run: small, objective costf2, saving of its net electrical energy at the drives" in printed
    assert "b/run: small, objective battery_energy, saving of its battery energy at the battery" in printed
    battery = result["energy"]["battery_energy_saved_percent"]
    net = result["improvement"]["net_energy_saved_percent"]
    assert abs(battery - net) > 0.01  # the two savings differ: the test tells them apart
    saving = [line.split()[-1] for line in printed.splitlines() if line.startswith("  optimal")]
    assert saving == [f"{net:+.2f}", f"{battery:+.2f}"]
    with (out / "comparison.csv").open() as handle:
        table = list(csv.DictReader(handle))
    assert [r["run"] for r in table] == ["a/run", "a/run", "b/run", "b/run"]
    for row in (table[1], table[3]):
        assert float(row["battery energy saving vs initial [%]"]) == pytest.approx(battery, rel=1e-9)
        assert float(row["net electrical energy saving vs initial [%]"]) == pytest.approx(net, rel=1e-9)


def _copies(small_run: Path, tmp_path: Path, objectives: tuple[str, ...]) -> list[Path]:
    """Copies of the small run's folder, one per objective, each result naming that objective."""
    folders = []
    for objective in objectives:
        folder = tmp_path / objective
        shutil.copytree(small_run, folder)
        data = json.loads((folder / "result.json").read_text())
        data["energy"]["objective"] = objective
        (folder / "result.json").write_text(json.dumps(data))
        folders.append(folder)
    return folders


def test_compare_saving_of_a_registered_objective_is_of_the_energy_it_declares(small_run: Path, tmp_path: Path) -> None:
    """An objective registered as measured by the battery energy gets the battery energy's saving.

    Its name is not ``battery_energy``: what counts is its ``measured_by``. An objective this process
    has not registered gets the net electrical energy's.
    """
    from hiab_sim.study.analysis.compare import BATTERY, NET, read_runs, rows
    from hiab_sim.study.nlp.objectives import BatteryEnergyCost, register_objective, unregister_objective

    class BatteryCopy(BatteryEnergyCost):
        name = "battery_copy"

    folders = _copies(small_run, tmp_path, ("battery_copy", "elsewhere_registered"))
    register_objective("battery_copy", BatteryCopy)
    try:
        runs = read_runs(folders)
    finally:
        unregister_objective("battery_copy")
    assert [run.saved for run in runs] == [BATTERY, NET]
    result = json.loads((small_run / "result.json").read_text())
    optimal = [row for row in rows(runs) if row.design == "optimal"]
    assert optimal[0].saving == pytest.approx(result["energy"]["battery_energy_saved_percent"], rel=1e-9)
    assert optimal[1].saving == pytest.approx(result["improvement"]["net_energy_saved_percent"], rel=1e-9)


def test_compare_reads_each_result_once(small_run: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``read_runs`` reads each folder's result.json once (its summary holds the objective)."""
    from hiab_sim.results import read
    from hiab_sim.study.analysis.compare import read_runs

    folders = _copies(small_run, tmp_path, ("costf2", "battery_energy"))
    reads: list[Path] = []
    original = read.read_json_as

    def counted(kind: type, path: Path) -> object:
        reads.append(Path(path))
        return original(kind, path)

    monkeypatch.setattr(read, "read_json_as", counted)
    assert [run.objective for run in read_runs(folders)] == ["costf2", "battery_energy"]
    assert [p for p in reads if p.name == "result.json"] == [f / "result.json" for f in folders]


def test_every_result_energy_an_objective_may_name_has_a_compare_column() -> None:
    """Each of the objective registry's RESULT_ENERGIES maps to one of compare's energy columns with a saving."""
    from hiab_sim.study.analysis.compare import MEASURED, SAVING
    from hiab_sim.study.nlp.objectives import OBJECTIVES, RESULT_ENERGIES

    assert set(MEASURED) == set(RESULT_ENERGIES)
    assert all(column in SAVING for column in MEASURED.values())
    assert {name: factory.measured_by for name, factory in OBJECTIVES.items()} == {
        "costf2": None,
        "battery_energy": "battery_energy",
    }


def test_run_labels_carry_no_root() -> None:
    """A folder whose whole path ends another's is labelled by that path less the root: ``a/run``, not ``//a/run``."""
    from hiab_sim.study.analysis.compare import run_labels

    assert run_labels(["/a/run", "/b/a/run"]) == ["a/run", "b/a/run"]
    assert run_labels(["/b/a/run", "/a/run"]) == ["b/a/run", "a/run"]
    assert run_labels(["/x/run", "/y/run", "/x/run"]) == ["x/run", "y/run", "x/run (2)"]


def test_compare_rejects_bad_folders_with_one_line(small_run: Path, tmp_path: Path, capsys) -> None:
    """A missing folder, a folder without a result and a truncated result exit 2 with one line; nothing is written."""
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / "result.json").write_text(json.dumps({"crane": "xs031", "optimal": {}}))
    for folder in (tmp_path / "nope", tmp_path / "empty", broken):
        folder.mkdir(exist_ok=True) if folder.name == "empty" else None
        assert main(["compare", str(small_run), str(folder), "--out", str(tmp_path / "cmp")]) == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
    assert not (tmp_path / "cmp").exists()

"""Tools on a machine file's result folder: the design report and ``compare`` beside a crane file's result.

The report of an excavator run names its decision variables, the pivots they move and the
structure of its designs (pins, screws, frequencies) with nothing loaded from outside the file;
``compare`` puts an excavator run and an XS 031 run in one table, each variable and actuator under
its own name, NaN where a machine lacks it, and the numbers equal the results' own.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest
from browser_helper import References
from machine_result_helper import excavator_result
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.results.read import read_result

#: Whole commands (optimize, report, compare) on two small runs: not in the fast tier.
pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def excavator_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return excavator_result(tmp_path_factory.mktemp("excavator"))


@pytest.fixture(scope="module")
def crane_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("crane")
    study = write_study(folder, small_study())
    assert main(["optimize", str(study), "--out", str(folder / "out"), "--no-video", "--quiet", "--no-figures"]) == 0
    return folder / "out"


def test_report_of_a_machine_result_states_its_variables_pivots_and_structure(excavator_run: Path) -> None:
    out = excavator_run / "report.html"
    assert main(["report", str(excavator_run), "-o", str(out)]) == 0
    html = out.read_text()
    parser = References()
    parser.feed(html)
    assert parser.tags == []  # nothing loaded from outside the file
    result = read_result(excavator_run)
    design = result.optimal.lengths if result.buildable is None else result.buildable.lengths
    for name, value in zip(design.names, design.values, strict=True):  # type: ignore[union-attr]
        assert f"{name} = {value:.4f} m" in html, name
    assert "bucket.rocker" in html or "bucket.base" in html  # a moved pivot of the four-bar, in its link's frame
    assert result.structure is not None
    most = result.structure.optimal.most_loaded_pin
    assert f"Most loaded pin of the optimal design: {most}" in html
    for name in result.structure.optimal.buckling:
        assert f"<td>{name}</td>" in html


def test_compare_puts_machine_and_crane_results_in_one_table_by_name(
    excavator_run: Path, crane_run: Path, tmp_path: Path
) -> None:
    out = tmp_path / "cmp"
    assert main(["compare", str(crane_run), str(excavator_run), "--out", str(out)]) == 0
    with (out / "comparison.csv").open() as handle:
        table = list(csv.DictReader(handle))
    assert [r["design"] for r in table] == ["initial", "optimal", "initial", "optimal"]
    excavator = json.loads((excavator_run / "result.json").read_text())
    crane = json.loads((crane_run / "result.json").read_text())
    for row in table[2:]:
        entry = excavator[row["design"]]
        for name, value in zip(entry["lengths"]["names"], entry["lengths"]["values"], strict=True):
            assert float(row[f"{name.replace('.', ' ')} [mm]"]) == pytest.approx(1e3 * value, rel=1e-15)
        assert math.isnan(float(row["lift L [mm]"])) and math.isnan(float(row["lift peak force [kN]"]))
        force = entry["actuators"]["bucket"]["peak_force_N"]
        assert float(row["bucket peak force [kN]"]) == pytest.approx(force / 1e3, rel=1e-15)
    for row in table[:2]:
        assert float(row["tilt Lc [mm]"]) == pytest.approx(
            1e3 * crane[row["design"]]["lengths"]["tilt"]["Lc"], rel=1e-15
        )
        assert math.isnan(float(row["boom L [mm]"]))
    assert (out / "comparison.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

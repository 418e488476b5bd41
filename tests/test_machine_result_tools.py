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
import shlex
from pathlib import Path

import numpy as np
import pytest
from browser_helper import References
from machine_result_helper import excavator_result

from hiab_sim.cli import main
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.results.read import read_result, result_machine
from hiab_sim.study.machines.machine_model import MachineModel

#: Whole commands (optimize, report, compare) on two small runs: not in the fast tier.
pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def excavator_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return excavator_result(tmp_path_factory.mktemp("excavator"))


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
    excavator_run: Path, small_run: Path, tmp_path: Path
) -> None:
    out = tmp_path / "cmp"
    assert main(["compare", str(small_run), str(excavator_run), "--out", str(out)]) == 0
    with (out / "comparison.csv").open() as handle:
        table = list(csv.DictReader(handle))
    assert [r["design"] for r in table] == ["initial", "optimal", "initial", "optimal"]
    excavator = json.loads((excavator_run / "result.json").read_text())
    crane = json.loads((small_run / "result.json").read_text())
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


def test_machine_result_reports_a_buildable_design_that_serves_its_range(excavator_run: Path, tmp_path: Path) -> None:
    """The rounded design is on the 1 mm grid within 1 mm of the optimum and its mjcf command runs.

    Its strokes, by an independent closure (the forward kinematics), stay in [0, stroke] over the
    buildable range.
    """
    result = read_result(excavator_run)
    b = result.buildable
    assert b is not None and b.crane_check.passed and b.tolerance_check.passed and b.recheck.passed
    rounded, optimal = np.asarray(b.lengths.values), np.asarray(result.optimal.lengths.values)  # type: ignore[union-attr]
    assert np.all(np.abs(rounded - optimal) <= b.tolerance_m + 1e-12)
    assert np.allclose(rounded / b.tolerance_m, np.round(rounded / b.tolerance_m), atol=1e-9)
    machine = result_machine(excavator_run, result).with_design(rounded, check_bounds=False)
    ranges = MachineModel(result_machine(excavator_run, result), ("tcp_angle",)).buildable_ranges(b.stroke_margin_m)
    for chain, (lo, hi) in zip([c for c in machine.chains if c.kind != "direct"], ranges, strict=True):
        q = np.tile([0.5 * sum(machine.joint_link(j).joint_range) for j in machine.joint_names], (101, 1))
        q[:, machine.joint_names.index(chain.joint)] = np.linspace(lo, hi, 101)
        x = forward_kinematics(machine, q).stroke[chain.name]
        assert float(np.min(x)) >= -1e-12 and float(np.max(x)) <= chain.actuator.stroke + 1e-12, chain.name
    argv = shlex.split(b.mjcf_command)[1:]
    assert main([*argv, "-o", str(tmp_path / "built.xml")]) == 0
    assert (tmp_path / "built.xml").read_text().startswith("<mujoco")

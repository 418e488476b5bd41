"""Cross-validation study: MuJoCo and analytic paths agree; the validate command writes its report."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from hiab_sim.cli import main
from hiab_sim.crane.description import Crane
from hiab_sim.crane.mechanism import check_lengths
from hiab_sim.resources import shipped
from hiab_sim.validation import (
    DEFAULT_CASES,
    load_cases,
    mujoco_path,
    random_link_lengths,
    run_case,
    with_samples,
)

TOLERANCES, SPECS = load_cases(DEFAULT_CASES)
UPDATE_README = Path(__file__).resolve().parents[1] / "validate" / "update_readme.py"


def test_case_file_covers_every_required_case() -> None:
    """The shipped cases: random states, trajectory, >= 20 length sets, static; each with and without payload."""
    kinds = {(s.kind, s.payload is not None) for s in SPECS}
    assert kinds == {(k, p) for k in ("random_states", "trajectory", "random_lengths", "static") for p in (False, True)}
    assert min(s.length_sets for s in SPECS if s.kind == "random_lengths") >= 20
    assert TOLERANCES.force_relative <= 1e-6 and TOLERANCES.velocity_absolute <= 1e-9


@pytest.mark.parametrize("spec", with_samples(SPECS, 12), ids=lambda s: s.name)
def test_mujoco_and_analytic_paths_agree_on_a_fast_subset(crane: Crane, spec: object) -> None:
    """Forces within 1e-6 of each actuator's peak, velocities within 1e-9 m/s, both energy balances hold."""
    result = run_case(crane, spec, mujoco_path(crane), TOLERANCES)  # type: ignore[arg-type]
    assert max(result.force_rel_error) <= 1e-6
    assert max(result.velocity_abs_error) <= 1e-9
    assert result.balance_analytic <= 1e-6
    assert result.balance_mujoco <= 1e-6
    assert result.passed


def test_random_link_lengths_are_feasible_and_distinct(crane: Crane) -> None:
    """Twenty random link-length sets all pass check_lengths and differ from each other."""
    sets = random_link_lengths(crane, np.random.default_rng(0), 20)
    for lengths in sets:
        check_lengths(crane, lengths)
    values = np.array([s.as_array() for s in sets])
    assert len({tuple(v) for v in values.round(9)}) == 20
    assert np.all(np.ptp(values, axis=0) > 1e-3)


@pytest.mark.e2e
def test_validate_command_writes_report_table_and_plots(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`hiab-sim validate --samples small` exits 0 and writes report.json, table.md and one plot per case."""
    assert main(["validate", "--samples", "small", "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["passed"] is True
    assert len(report["cases"]) == len(SPECS)
    assert (tmp_path / "table.md").read_text().startswith("| case |")
    assert len(list(tmp_path.glob("forces_*.png"))) == len(SPECS)
    assert not list(tmp_path.glob(".*")), "temporary files left behind"
    assert "validation passed" in capsys.readouterr().out


def test_validate_exits_1_when_an_error_exceeds_its_tolerance(tmp_path: Path) -> None:
    """A tolerance below round-off makes the command fail with status 1."""
    cases = tmp_path / "cases.yaml"
    cases.write_text(
        "tolerances: {force_relative: 1.0e-20}\n"
        "cases:\n  - {name: static, kind: static, samples: 4, seed: 1, payload: none}\n"
    )
    assert main(["validate", "--cases", str(cases), "--out", str(tmp_path / "out")]) == 1
    assert json.loads((tmp_path / "out" / "report.json").read_text())["passed"] is False


@pytest.mark.parametrize(
    "argv",
    [["--crane", "no-such-crane"], ["--cases", "no-such-file.yaml"]],
    ids=["unknown crane", "missing case file"],
)
def test_validate_bad_input_exits_2(tmp_path: Path, argv: list[str]) -> None:
    """Bad input is reported on one line with exit status 2."""
    assert main(["validate", *argv, "--out", str(tmp_path)]) == 2


def test_validate_rejects_a_non_positive_sample_count() -> None:
    """--samples 0 is an argument error (status 2)."""
    with pytest.raises(SystemExit) as info:
        main(["validate", "--samples", "0"])
    assert info.value.code == 2


def test_update_readme_replaces_only_the_marked_block(tmp_path: Path) -> None:
    """validate/update_readme.py swaps the table between the markers and leaves the rest alone."""
    spec = importlib.util.spec_from_file_location("update_readme", UPDATE_README)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    readme = tmp_path / "README.md"
    readme.write_text(f"intro\n{module.START}\nold table\n{module.END}\noutro\n")
    table = tmp_path / "table.md"
    table.write_text("| new | table |\n")
    assert module.main(["--table", str(table), "--readme", str(readme), "--check"]) == 1
    assert module.main(["--table", str(table), "--readme", str(readme)]) == 0
    assert readme.read_text() == f"intro\n{module.START}\n| new | table |\n{module.END}\noutro\n"
    assert module.main(["--table", str(table), "--readme", str(readme), "--check"]) == 0


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda d: d["tolerances"].update(force_relativ=1e-6), "force_relativ"),
        (lambda d: d["cases"][0].update(samples="many"), "cases.random_states.samples"),
        (lambda d: d["cases"][1].pop("kind"), "cases.trajectory: missing key(s) ['kind']"),
        (lambda d: d["cases"][2].pop("name"), "cases.2: missing key(s) ['name']"),
        (lambda d: d["cases"][3].update(kind="wobble"), "cases.static.kind"),
        (lambda d: d["tolerances"].update(balance_relative=-1.0), "tolerances.balance_relative"),
    ],
)
def test_bad_case_file_exits_2_with_one_line_naming_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], edit: Any, field: str
) -> None:
    """Unknown tolerance key, non-numeric samples, missing case fields: exit 2, one line naming the field."""
    document = yaml.safe_load(shipped("cases", "cases").read_text())
    edit(document)
    bad = tmp_path / "cases.yaml"
    bad.write_text(yaml.safe_dump(document))
    assert main(["validate", "--cases", str(bad), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert field in err and "Traceback" not in err and len(err.splitlines()) == 1
    assert not (tmp_path / "out").exists()

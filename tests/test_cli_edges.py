"""The CLI's edges: mistyped names, lengths that cannot be built, and shipped files free of internal references."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from hiab_sim.cli import main

REPO = Path(__file__).resolve().parents[1]


def test_a_mistyped_study_name_suggests_only_studies(capsys: pytest.CaptureFixture[str]) -> None:
    """The message lists shipped studies and the closest one; not the EMLA set, crane file or sweeps beside them."""
    assert main(["optimize", "xs031_spirl", "--no-video", "--no-figures"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "did you mean 'xs031_spiral'?" in err
    listed = err.split("shipped name (", 1)[1].split(")", 1)[0].split(", ")
    assert "xs031_spiral" in listed and "xs031_duty_mix" in listed
    for not_a_study in ("emla_seed_scale", "xs031_seed_scale_crane", "sweeps/xs031_payload_gear"):
        assert not_a_study not in listed


def test_a_length_set_that_cannot_be_built_names_the_lengths_given(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Mjcf --lengths with a lift L of 2 m: exit 2, one line naming --lengths and the lift chain's three lengths."""
    out = tmp_path / "x.xml"
    assert main(["mjcf", "--lengths", "2,0.085,0.745,1.132,0.085,0.745", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "--lengths 2,0.085,0.745" in err and "lift chain given as L = 2 m, Lc0 = 0.085 m, Lc = 0.745 m" in err
    assert not out.exists()


def _shipped_files() -> list[Path]:
    folders = ("hiab_sim", "optimize", "validate", "assets")
    suffixes = {".py", ".yaml", ".xml", ".csv", ".md"}
    return [p for f in folders for p in (REPO / f).rglob("*") if p.suffix in suffixes and "__pycache__" not in p.parts]


def test_shipped_files_carry_no_issue_numbers_or_internal_paths() -> None:
    """No 'issue 13' and no path of the team's shared folder in any file the wheel ships."""
    pattern = re.compile(r"\bissue\s*#?\d+|\(issue\b|shared/reference|/work/", re.IGNORECASE)
    found = [f"{p.relative_to(REPO)}: {m.group(0)}" for p in _shipped_files() for m in pattern.finditer(p.read_text())]
    assert found == []


def test_simulate_closing_lines_read_the_heavier_load_as_its_energy_not_a_failure() -> None:
    """The extra energy of a heavier end mass is named as the load's, with the report's own numbers."""
    from hiab_sim.cli.simulate_summary import closing_lines

    nominal = {"energy_difference_percent": -0.06, "tcp_error_mm": {"max": 0.83}, "payload_error": 0.0}
    heavy = {
        "energy_difference_percent": 34.34,
        "tcp_error_mm": {"max": 4.65},
        "payload_error": 0.2,
        "extra_energy_J": 1368.6,
        "nominal": nominal,
    }
    (line,) = closing_lines({"designs": {"optimal": heavy}})
    assert line.startswith("optimal: the closed loop uses -0.06 % energy against the plan, tracking within 0.83 mm")
    assert "end mass +20 % it needs 1369 J more (+34.34 % against the plan" in line and "not a failure" in line


def test_an_all_infeasible_energy_map_says_which_limit_binds_and_what_to_map(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """lift.L x tilt.L at the start has no feasible cell: console and figure name the limit and a chain's lengths."""
    import json

    assert main(["energy-map", "--vars", "lift.L,tilt.L", "--grid", "10", "--out", str(tmp_path)]) == 0
    printed = capsys.readouterr().out
    summary = json.loads((tmp_path / "energy_map.json").read_text())
    assert summary["best_feasible_cell"] is None
    note = next(line for line in printed.splitlines() if line.startswith("No feasible cell of 100"))
    chain = note.split(" cells break ")[1].split()[0]
    assert f"map {chain}.Lc0 and {chain}.Lc instead" in note
    assert "_" not in note.split(" cells break ")[1].split(" with ")[0]  # the limit in words, not a row name
    # beside the most frequent limit, the next two with their counts, the rest counted: as energy_map.json has them
    counts = sorted(summary["infeasible_cells_by_binding_constraint"].values(), reverse=True)
    named = [int(note.split(" cells break ")[0].rsplit(" ", 1)[1])]
    named += [int(part.split(" break ")[0]) for part in note.split("(the other cells: ")[1].split("; ")[:2]]
    assert named == counts[:3]
    assert f" and {len(counts) - 3} more limit" in note

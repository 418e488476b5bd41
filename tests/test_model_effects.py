"""The default study per EMLA model level: the levels change only the model, the table is the recorded runs'.

The table's runs take minutes (five optimisations); CI checks what they recorded
(docs/results/data/xs031_spiral_model_effects.json) against the optima tests/data/shipped_optima.json
holds for the same studies, read through that record's own script, and the page against the data.
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import pytest
from script_helper import load_script

from hiab_sim.docs_site.results_data import RunData, load_data
from hiab_sim.docs_site.results_page import render_block
from hiab_sim.errors import ConfigError
from hiab_sim.study.analysis.model_effects import LEVELS, ModelLevel, level_study

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "optimize" / "xs031_spiral.yaml"
DATA = load_data()
TABLE = "xs031_spiral_model_effects"


def _rows() -> dict[str, dict]:
    if TABLE not in DATA:
        pytest.skip(f"no recorded {TABLE} in docs/results/data (scripts/results_pages.sh records it)")
    return {r["key"]: r for r in DATA[TABLE]["model_effects"]["rows"]}


def test_each_level_changes_only_the_emla_model_and_the_hold(tmp_path: Path) -> None:
    """Losses, R_s(T) and the hold are on exactly where the level says; grid, bounds, tasks stay the base's."""
    from hiab_sim.study.spec.study_file import load_study

    base = load_study(BASE)
    expected = {  # level -> (drive losses on, R_s rises with temperature, hold of the rest)
        "paper": (False, False, None),
        "drive_losses": (True, False, None),
        "hot_windings": (True, True, None),
        "hold_brake": (True, True, "brake"),
        "hold_motor": (True, True, "motor"),
    }
    assert [level.key for level in LEVELS] == list(expected)
    for level in LEVELS:
        study = level_study(BASE, level, tmp_path)
        assert study.energy.duty is not None
        lift = study.emlas["lift"]
        losses_on = lift.losses is not None and lift.losses.transmission_efficiency_forward < 1.0
        got = (losses_on, lift.winding is not None, study.energy.duty.hold_mode(study.emlas))
        assert got == expected[level.key], level.key
        for field in ("grid", "bounds", "tracking", "solver", "initial_lengths", "spline"):
            assert getattr(study, field) == getattr(base, field), (level.key, field)
        # the one task is the base's, named after the level's study
        assert [replace(t, name=base.name) for t in study.tasks] == list(base.tasks), level.key
        assert study.energy.objective == base.energy.objective
        assert study.energy.duty is not None and base.energy.duty is not None
        assert study.energy.duty.cycles_per_hour == base.energy.duty.cycles_per_hour


def test_a_level_of_unknown_model_is_refused() -> None:
    """An EMLA choice or hold outside the known ones raises ConfigError naming the level."""
    with pytest.raises(ConfigError, match="odd"):
        ModelLevel("odd", "odd", "lossless", "none", None)
    with pytest.raises(ConfigError, match="odd"):
        ModelLevel("odd", "odd", "base", "crane", None)


def test_the_recorded_rows_are_the_shipped_optima_of_the_same_studies() -> None:
    """The hold_brake row is the default study's recorded optimum, the paper row seed_faithful's (1e-9, 1e-8 m).

    Both come from tests/data/shipped_optima.json through scripts/shipped_optima.py, runs of
    ``hiab-sim optimize`` on optimize/xs031_spiral.yaml and optimize/seed_faithful.yaml, not from the table's.
    """
    rows = _rows()
    checker = load_script("shipped_optima", ROOT / "scripts" / "shipped_optima.py")
    for key, study in (("hold_brake", "xs031_spiral"), ("paper", "seed_faithful")):
        want = checker.expected(study)
        row = rows[key]
        for got, recorded in (
            (row["battery_energy_J"], want["energies"]["optimal_battery_energy_J"]),
            (row["initial_battery_energy_J"], want["energies"]["initial_battery_energy_J"]),
        ):
            assert got == pytest.approx(recorded, rel=1e-9, abs=0.0), key
        xi = checker._xi(row["lengths"])
        assert max(abs(a - b) for a, b in zip(xi, want["xi_m"], strict=True)) <= checker.XI_TOLERANCE, key
        assert row["iterations"] == want["iterations"], key


def test_the_motor_hold_is_infeasible_on_the_lift_winding() -> None:
    """At 60 cycles/hour the lift's motor cannot hold the rest: the feasibility phase names its winding."""
    row = _rows()["hold_motor"]
    assert row["status"] == "infeasible"
    assert "lift" in row["message"] and "winding" in row["message"]


def _kj(text: str) -> list[float]:
    return [float(v) for v in re.findall(r"([+-]?\d+\.\d+) kJ", text)]


def test_the_block_and_the_energy_page_show_the_recorded_rows() -> None:
    """Each row's energy and its change against the row it names, read back from the Markdown (0.5 J).

    docs/energy.md carries the same table as the generated block of docs/results/energy.md.
    """
    rows = _rows()
    block = render_block("energy-model-effects", RunData(DATA))
    lines = [line for line in block.splitlines() if line.startswith("| ") and "kJ" in line]
    optimised = [r for r in rows.values() if r["status"] == "optimised"]
    assert len(lines) == len(optimised)
    for line, r in zip(lines, optimised, strict=True):
        values = _kj(line)
        assert values[0] == pytest.approx(r["battery_energy_J"] / 1e3, abs=5e-4)
        if r.get("compared_with") is not None:
            before = rows[r["compared_with"]]["battery_energy_J"]
            assert values[1] == pytest.approx((r["battery_energy_J"] - before) / 1e3, abs=5e-4)
    assert block in (ROOT / "docs" / "energy.md").read_text()

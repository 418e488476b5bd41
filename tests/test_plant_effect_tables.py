"""The effect study's compact table and ``effects.md``: what a reader of the README gets from the numbers."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from hiab_sim.env.effect_report import compact_effect_table, effect_markdown, write_effect_markdown


def _row(dc_percent: float, tcp_max_mm: float, battery_percent: float | None = None) -> dict[str, object]:
    row: dict[str, object] = {
        "dc_bus_energy_J": 1000.0 * (1.0 + dc_percent / 100.0),
        "dc_bus_energy_difference_percent": dc_percent,
        "energy_difference_to_5ms_grid_percent": dc_percent,
        "tcp_error_mm": {"rms": tcp_max_mm / 2.0, "max": tcp_max_mm},
        "peak_current_A": {"a": 10.0, "b": 5.0},
        "peak_voltage_V": {"a": 200.0, "b": 100.0},
    }
    if battery_percent is not None:
        row["battery_energy_J"] = 2000.0 * (1.0 + battery_percent / 100.0)
        row["battery_energy_difference_percent"] = battery_percent
    return row


def _report(battery: bool) -> dict[str, object]:
    """Three variants; with ``all`` the optimum is dearer at the battery (not at the DC bus)."""

    def b(value: float) -> float | None:
        return value if battery else None

    variants = {
        "ideal": {
            "initial": _row(0.2, 0.09, b(-2.0)),
            "optimal": _row(0.22, 0.94, b(-1.16)),
            "optimal_below_initial": True,
            "optimal_below_initial_battery": True,
        },
        "joint_friction": {
            "initial": _row(13.39, 0.85, b(10.81)),
            "optimal": _row(13.641, 1.244, b(11.994)),
            "optimal_below_initial": True,
            "optimal_below_initial_battery": True,
        },
        "all": {
            "initial": _row(15.8, 2.1, b(13.15)),
            "optimal": _row(16.68, 2.4, b(14.98)),
            "optimal_below_initial": True,
            "optimal_below_initial_battery": False,
        },
    }
    report: dict[str, object] = {"plant": "realistic", "cycles": 1, "variants": variants}
    if battery:
        report["battery_energy"] = "the closed loop's battery model"
    return report


def test_the_compact_table_has_one_column_per_variant_and_five_lines() -> None:
    """Battery energy vs prediction and TCP max error per variant (initial / optimal), and which design is cheaper."""
    lines = compact_effect_table(_report(battery=True)).splitlines()
    assert lines == [
        "| effect | ideal | joint_friction | all |",
        "|---|---:|---:|---:|",
        "| closed-loop battery energy vs predicted (initial / optimal) "
        "| -2.00 / -1.16 % | +10.81 / +11.99 % | +13.15 / +14.98 % |",
        "| TCP max error (initial / optimal) [mm] | 0.09 / 0.94 | 0.85 / 1.24 | 2.10 / 2.40 |",
        "| optimum stays cheaper (at the battery) | yes | yes | **no** |",
    ]


def test_without_a_battery_the_compact_table_reads_the_dc_bus() -> None:
    """A result without a battery: the DC-bus energy against the optimiser's prediction, cheaper at the DC bus."""
    lines = compact_effect_table(_report(battery=False)).splitlines()
    assert lines[2] == (
        "| closed-loop DC-bus energy vs predicted (initial / optimal) | +0.20 / +0.22 % | +13.39 / +13.64 % "
        "| +15.80 / +16.68 % |"
    )
    assert lines[4] == "| optimum stays cheaper (at the DC bus) | yes | yes | yes |"


def test_one_design_leaves_out_the_comparison() -> None:
    """Only the optimal design simulated: its values alone, no "cheaper" row."""
    report = _report(battery=True)
    for entry in report["variants"].values():  # type: ignore[attr-defined]
        del entry["initial"]
    lines = compact_effect_table(report).splitlines()
    assert len(lines) == 4
    assert lines[3] == "| TCP max error (optimal) [mm] | 0.94 | 1.24 | 2.40 |"


def test_effects_md_holds_the_compact_and_the_full_table(tmp_path: Path) -> None:
    """``effects.md`` opens with the plant and cycles, then the compact table, then the full table."""
    report = _report(battery=True)
    path = write_effect_markdown(tmp_path / "effects.md", report)
    text = path.read_text(encoding="utf-8")
    assert text == effect_markdown(report)
    assert text.startswith("# Plant effects: realistic plant, 1 cycle(s) per run")
    assert compact_effect_table(report) in text
    assert text.count("| all | ") == 2  # initial and optimal rows of the full table


@pytest.mark.e2e
def test_the_replanned_battery_energy_is_one_cycles_as_the_closed_loops() -> None:
    """With the study's duty the re-plan's battery energy is its cycle's, not the cycle's and the rest's.

    The closed loop and the nominal prediction leave the rest between cycles out; the re-planned optimum's
    number must too, or knowing the load would seem to cost the rest's standby (3.5 kJ on the default study).
    """
    from hiab_sim.env import default_result_dir
    from hiab_sim.env.effects import replanned_summary

    folder = default_result_dir()
    duty = json.loads((folder / "result.json").read_text(encoding="utf-8"))["energy"]["optimal"]["duty"]
    summary = replanned_summary(folder)
    assert summary["predicted_battery_J"] == duty["cycle_battery_energy_J"]
    assert duty["rest_battery_energy_J"] > 0.0
    assert summary["predicted_battery_J"] < duty["battery_energy_J"] - 0.5 * duty["rest_battery_energy_J"]


def test_every_plant_effect_has_words_for_the_figure() -> None:
    """The effect figure labels each variant in words: every effect of the plant file, the ideal plant and all."""
    from hiab_sim.env.effect_report import EFFECT_WORDS
    from hiab_sim.env.plant.config import EFFECTS

    assert {*EFFECTS, "ideal", "all"} <= set(EFFECT_WORDS)
    assert all("_" not in words for words in EFFECT_WORDS.values())

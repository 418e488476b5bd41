"""The README's tables of measured numbers are the recorded runs' numbers, rounded as printed."""

from __future__ import annotations

import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "docs" / "results" / "data"


def _row(label: str) -> list[str]:
    """The cells after the first of the README table row whose first cell starts with ``label``."""
    for line in (ROOT / "README.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("|") and cells[0].startswith(label):
            return cells[1:]
    raise AssertionError(f"README has no table row starting {label!r}")


def test_the_model_effect_row_is_the_recorded_re_optimised_runs() -> None:
    """Each model level's battery energy [kJ] and saving [%] in the README equals the recorded row."""
    rows = json.loads((DATA / "xs031_spiral_model_effects.json").read_text())["model_effects"]["rows"]
    by_key = {r["key"]: r for r in rows}
    printed = _row("energy (saving")
    levels = ("paper", "drive_losses", "hot_windings", "hold_brake")
    assert len(printed) == len(levels)
    for cell, key in zip(printed, levels, strict=True):
        match = re.fullmatch(r"([0-9.]+) kJ \(([0-9.]+) %\)", cell)
        assert match is not None, cell
        row = by_key[key]
        assert match.group(1) == f"{row['battery_energy_J'] / 1e3:.2f}", key
        assert match.group(2) == f"{row['battery_energy_saved_percent']:.1f}", key
    assert by_key["hold_motor"]["status"] == "infeasible"


#: The recorded effect studies of the README's plant table: (row label, ``plant_effects.json`` of the run).
PLANT_RUNS = (
    ("XS 031 spiral", ROOT / "tests" / "data" / "plant_effects_xs031_spiral.json"),
    ("eXact digging", ROOT / "tests" / "data" / "plant_effects_exact_digging.json"),
)


def _cells(line: str) -> list[str]:
    """The stripped cells of one markdown table line."""
    return [c.strip() for c in line.strip().strip("|").split("|")]


def test_the_plant_effect_rows_are_the_recorded_runs_compact_tables() -> None:
    """Each README row of the plant table is the command's compact table of the recorded run, cell for cell."""
    from hiab_sim.env.effect_report import compact_effect_table

    header = _row("closed loop vs plan")
    for label, path in PLANT_RUNS:
        report = json.loads(path.read_text())
        lines = compact_effect_table(report).splitlines()
        names = _cells(lines[0])[1:]
        assert names == header, label
        by_first = {cells[0]: cells[1:] for cells in map(_cells, lines[2:])}
        energy = next(v for k, v in by_first.items() if k.startswith("closed-loop battery energy"))
        tcp = next(v for k, v in by_first.items() if k.startswith("TCP max error"))
        assert _row(f"{label}: battery energy") == energy, label
        assert _row(f"{label}: TCP max error") == tcp, label
        assert all(cell == "yes" for cell in by_first["optimum stays cheaper (at the battery)"]), label


def _result(run: str) -> dict:
    """The ``result`` of a recorded run (``docs/results/data/<run>.json``)."""
    return json.loads((DATA / f"{run}.json").read_text())["result"]


def _prose() -> str:
    """The README's text with its line breaks joined (a sentence may wrap)."""
    return " ".join((ROOT / "README.md").read_text().split())


def test_the_prose_numbers_are_the_recorded_runs() -> None:
    """The answer, the default study's iterations and both excavator studies' energies, rounded as printed.

    The README once said "the same 33 iterations" while the recorded default run took 29: prose
    numbers outside the tables drift unless something reads them back.
    """
    text = _prose()
    spiral = _result("xs031_spiral")
    built = spiral["buildable"]["lengths"]
    lift, tilt = (" / ".join(f"{built[c][k]:.3f}" for k in ("L", "Lc0", "Lc")) for c in ("lift", "tilt"))
    assert f"lift L / Lc0 / Lc = {lift} m and tilt {tilt} m" in text
    energy = spiral["energy"]
    assert (
        f"{energy['initial']['battery_energy_J'] / 1e3:.2f} kJ per duty period before and "
        f"{energy['optimal']['battery_energy_J'] / 1e3:.2f} kJ after (−{energy['battery_energy_saved_percent']:.1f} %)"
    ) in text
    assert f"the same {spiral['solver']['iterations']} iterations" in text
    lift = energy["optimal"]["thermal"]["lift"]
    assert f"runs at {lift['peak_winding_temperature_C']:.0f} °C (RMS torque {lift['rms_torque_Nm']:.1f} of" in text
    hydraulic = spiral["hydraulic_baseline"]["optimal"]
    at = {k: v["cycle_battery_energy_J"] / 1e3 for k, v in hydraulic["at_battery"].items()}
    assert f"the EMLAs take {hydraulic['emla_cycle_battery_energy_J'] / 1e3:.1f} kJ" in text
    assert f"would take {at['load_sensing']:.1f} kJ (load sensing" in text
    assert f"or {at['constant_pressure']:.1f} kJ (constant pressure)" in text
    assert f"(one electro-hydraulic actuator each) {at['pump_controlled']:.1f} kJ" in text
    for run, unit, digits in (("exact_digging", "kJ per duty period", 1), ("exact_duty_mix", "kJ per working hour", 0)):
        e = _result(run)["energy"]
        before, after = (e[d]["battery_energy_J"] / 1e3 for d in ("initial", "optimal"))
        assert f"{before:.{digits}f} → {after:.{digits}f} {unit} (−{e['battery_energy_saved_percent']:.1f} %" in text, (
            run
        )


def test_the_duty_mix_effect_numbers_are_the_recorded_per_task_runs() -> None:
    """The closed-loop page's per-task effect numbers of exact_duty_mix are the recorded run's; its claim holds there.

    ``tests/data/plant_effects_exact_duty_mix.json`` holds each task's ``plant_effects`` of ``simulation.json``:
    the ideal and all-effects DC-bus differences, the all-effects battery differences, the optimal design cheaper.
    """
    recorded = json.loads((ROOT / "tests" / "data" / "plant_effects_exact_duty_mix.json").read_text())
    text = " ".join((ROOT / "docs" / "results" / "closed-loop.md").read_text().split())

    def pair(variant: dict, key: str) -> str:
        return f"{variant['initial'][key]:+.2f} / {variant['optimal'][key]:+.2f} %"

    for entry in recorded["tasks"]:
        task, variants = entry["task"], entry["plant_effects"]["variants"]
        bus = "dc_bus_energy_difference_percent"
        assert f"{task} ideal {pair(variants['ideal'], bus)}" in text, task
        assert f"all effects {pair(variants['all'], bus)}" in text, task
        assert f"{pair(variants['all'], 'battery_energy_difference_percent')} for {task}" in text, task
        assert all(v["optimal_below_initial_battery"] and v["optimal_below_initial"] for v in variants.values()), task

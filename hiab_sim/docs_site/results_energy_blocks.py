"""Generated blocks of the energy page: objectives, thermal state, transmission co-design, drive losses, hydraulics.

Each block is a function of :class:`~hiab_sim.docs_site.results_data.RunData` returning Markdown from
the XS 031 studies' committed ``result.json`` fields (energies in J at the boundary the field names).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from hiab_sim.docs_site.markdown import table
from hiab_sim.docs_site.results_data import RunData
from hiab_sim.docs_site.results_format import CHAINS, LIFT, chain_lengths, kilo, length_headers, lengths, percent_change

DEFAULT, ENERGY, CODESIGN, PAYLOAD = "xs031_spiral", "xs031_spiral_energy", "xs031_codesign", "xs031_spiral_payload"
#: The default study re-optimised per EMLA model level (:mod:`hiab_sim.study.analysis.model_effects`).
MODEL_EFFECTS = "xs031_spiral_model_effects"


def objectives(runs: RunData) -> str:
    """The start and the optima of the two objectives: lengths, battery energy per duty period, costf2."""
    start = runs.result(DEFAULT)
    battery0 = start("energy.initial.battery_energy_J")
    rows: list[tuple[object, ...]] = [
        (
            "start (built XS 031)",
            *(lengths(start("initial.lengths"), c, 4) for c in CHAINS),
            f"{battery0:.1f} J",
            f"{start('energy.initial.costf2_W2s'):.4g}",
        )
    ]
    for study in (DEFAULT, ENERGY):
        r = runs.result(study)
        battery = r("energy.optimal.battery_energy_J")
        rows.append(
            (
                f"`{study}` ({r('energy.objective')})",
                *(lengths(r("optimal.lengths"), c, 4) for c in CHAINS),
                f"{battery:.1f} J ({percent_change(battery0, battery)})",
                f"{r('energy.optimal.costf2_W2s'):.4g}",
            )
        )
    header = ("design", *length_headers(), "battery energy", "costf2 [W² s]")
    return table(header, rows)


def drawn(runs: RunData) -> str:
    """Per-drive drawn and net energies of the default optimum, beside the battery's."""
    r = runs.result(DEFAULT)
    drawn_J, net_J = r("energy.optimal.drawn_energy_J"), r("energy.optimal.net_energy_J")
    per = ", ".join(f"{name} {kilo(drawn_J[name])} / {kilo(net_J[name])}" for name in drawn_J)
    return (
        f"At the default optimum the drives draw / net (kJ): {per}; summed, "
        f"{kilo(sum(drawn_J.values()))} kJ drawn, where the battery delivers "
        f"{kilo(r('energy.optimal.battery_energy_J'))} kJ per duty period ({r('energy.duty')})."
    )


def smoothing(runs: RunData) -> str:
    """What the smoothed drive losses add to the solver's battery energy on the energy study."""
    r = runs.result(ENERGY)
    return (
        f"On `{ENERGY}` at the optimum: the kinks' bound is {r('energy.optimal.smoothing_bound_J'):.3f} J, the "
        f"smoothed drive losses add {r('energy.optimal.drive_loss_smoothing_J'):.0f} J to the smooth value, and the "
        f"exact battery energy is {kilo(r('energy.optimal.battery_energy_J'))} kJ."
    )


def _thermal_cells(thermal: dict[str, Any]) -> list[str]:
    cells = []
    for t in thermal.values():
        cells.append(f"{t['rms_torque_Nm']:.2f} / {t['continuous_torque_Nm']:.0f} N m")
        cells.append(f"{t['peak_winding_temperature_C']:.1f} / {t['max_winding_temperature_C']:.0f} °C")
    return cells


def thermal(runs: RunData) -> str:
    """Each motor's RMS torque and peak winding temperature at the optima, with their limits."""
    rows = []
    motors: list[str] = []
    for study in (DEFAULT, ENERGY, CODESIGN, PAYLOAD):
        r = runs.result(study)
        t = r("energy.optimal.thermal")
        motors = list(t)
        rows.append((f"`{study}` ({r('energy.duty')})", *_thermal_cells(t)))
    header = ("study, optimum", *(f"{m} {q}" for m in motors for q in ("RMS / continuous", "winding peak / max")))
    return table(header, rows)


def _gears(row: dict[str, Any]) -> list[str]:
    """A co-design row's gear ratio of each chain's actuator, in the crane's chain order."""
    t = row["transmission"]
    return [f"{t[c]['gear_ratio']:g}" for c in CHAINS]


def codesign(runs: RunData) -> str:
    """Every transmission combination: battery energy at the start and at its mounting optimum."""
    r = runs.result(CODESIGN)
    best, reference = r("codesign.best"), r("codesign.reference")
    rows = []
    for i, row in enumerate(r("codesign.rows")):
        *gears, last = _gears(row)
        note = " (EMLA file: mounting alone)" if i == reference else (" (best)" if i == best else "")
        optimum = row.get("battery_energy_J")
        rows.append(
            (
                *gears,
                last + note,
                f"{row['initial_battery_energy_J']:.1f} J" if row.get("initial_battery_energy_J") else row["status"],
                row["status"] if optimum is None else f"{optimum:.1f} J",
            )
        )
    b = r("codesign.rows")[best]
    text = table((*(f"{c} G" for c in CHAINS), "battery energy at the start", "at the mounting optimum"), rows)
    return (
        f"{text}\n\nThe co-design saves **{r('codesign.codesign_saving_percent'):.1f} %** of the battery energy "
        f"against **{r('codesign.mounting_only_saving_percent'):.1f} %** for the mounting alone "
        f"({r('codesign.extra_saving_J'):.0f} J more per duty period); the best combination's mounting: "
        f"{chain_lengths(b['lengths'])}."
    )


def drive_losses(runs: RunData) -> str:
    """The drive losses of the energy study's optimum, summed over the drives, by kind."""
    r = runs.result(ENERGY)
    kinds: dict[str, float] = {}
    for losses in r("energy.optimal.drive_loss_energy_J").values():
        for kind, value in losses.items():
            kinds[kind] = kinds.get(kind, 0.0) + value
    parts = ", ".join(f"{kind.replace('_', ' ')} {value:.0f} J" for kind, value in kinds.items())
    return (
        f"On `{ENERGY}` at the optimum, summed over the drives: {parts}; battery energy "
        f"{kilo(r('energy.initial.battery_energy_J'))} → {kilo(r('energy.optimal.battery_energy_J'))} kJ "
        f"({percent_change(r('energy.initial.battery_energy_J'), r('energy.optimal.battery_energy_J'), 1)})."
    )


def _hydraulic_rows(runs: RunData) -> list[tuple[str, dict[str, Any]]]:
    return [
        ("built XS 031", runs.result(DEFAULT)("hydraulic_baseline.initial")),
        (f"`{DEFAULT}` optimum", runs.result(DEFAULT)("hydraulic_baseline.optimal")),
        (f"`{ENERGY}` optimum", runs.result(ENERGY)("hydraulic_baseline.optimal")),
        (f"`{CODESIGN}` optimum", runs.result(CODESIGN)("hydraulic_baseline.optimal")),
    ]


def hydraulic(runs: RunData) -> str:
    """EMLA battery energy against the cylinders at the pump motor input, and every variant at the battery."""
    pump_input, battery = [], []
    for label, h in _hydraulic_rows(runs):
        ls, cp = h["load_sensing"], h["constant_pressure"]
        pump_input.append(
            (
                label,
                f"{kilo(h['emla_battery_energy_J'])} kJ",
                f"{kilo(ls['input_energy_J'], 1)} kJ ({100 * ls['system_efficiency']:.1f} %)",
                f"{kilo(cp['input_energy_J'], 1)} kJ ({100 * cp['system_efficiency']:.1f} %)",
                f"{h['emla_saving_vs_load_sensing_percent']:.1f} % / "
                f"{h['emla_saving_vs_constant_pressure_percent']:.1f} %",
            )
        )
        at = h["at_battery"]
        battery.append(
            (
                label,
                f"{kilo(h['emla_cycle_battery_energy_J'])} kJ",
                *(
                    f"{kilo(at[v]['cycle_battery_energy_J'], 1)} kJ ({at[v]['emla_saving_percent']:.1f} %)"
                    for v in ("load_sensing", "constant_pressure", "pump_controlled")
                ),
            )
        )
    first = table(
        (
            "design",
            "EMLA battery, duty period",
            "hydraulic, load sensing (system efficiency)",
            "constant pressure",
            "EMLA saving vs LS / CP",
        ),
        pump_input,
    )
    second = table(
        (
            "design, one cycle at the battery",
            "EMLAs",
            "load sensing (EMLA saving)",
            "constant pressure",
            "pump-controlled, one EHA each",
        ),
        battery,
    )
    return f"{first}\n\n{second}"


def _infeasible_reason(message: str) -> str:
    """The violated limit of a feasibility phase's message (the text after its last ``): ``), else all of it."""
    return message.rsplit("): ", 1)[-1].strip()


def model_effects(runs: RunData) -> str:
    """The default study re-optimised per EMLA model level: battery energy, change, lift winding, saving."""
    rows_data = runs(MODEL_EFFECTS, "model_effects.rows")
    energy = {r["key"]: r["battery_energy_J"] for r in rows_data if r["status"] == "optimised"}
    rows: list[tuple[object, ...]] = []
    for r in rows_data:
        if r["status"] != "optimised":
            rows.append((r["label"], f"infeasible: {_infeasible_reason(r['message'])}", "", "", ""))
            continue
        battery, before = r["battery_energy_J"], energy.get(r.get("compared_with") or "")
        change = "" if before is None else f"{(battery - before) / 1e3:+.3f} kJ ({percent_change(before, battery, 1)})"
        rows.append(
            (
                r["label"],
                f"{battery / 1e3:.3f} kJ",
                change,
                f"{r['peak_winding_temperature_C'][LIFT]:.1f} °C",
                f"{r['battery_energy_saved_percent']:.2f} %",
            )
        )
    header = (
        "model",
        "battery energy per duty period at the optimum",
        "change",
        f"{LIFT} winding (peak)",
        "optimum's saving vs the built crane",
    )
    return table(header, rows)


BLOCKS: dict[str, Callable[[RunData], str]] = {
    "energy-objectives": objectives,
    "energy-drawn": drawn,
    "energy-smoothing": smoothing,
    "energy-thermal": thermal,
    "energy-codesign": codesign,
    "energy-drive-losses": drive_losses,
    "energy-hydraulic": hydraulic,
    "energy-model-effects": model_effects,
}

"""The effect study for people: its table, the compact table of ``effects.md``, the lines in words, the figure.

Everything here reads the ``plant_effects`` section that :func:`hiab_sim.env.effects.effect_study` builds
(a plain mapping, as ``simulation.json`` stores it); nothing is simulated again.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.style import COLOURS


def effect_table(report: dict[str, object]) -> str:
    """Markdown table of the effect study (docs/plant.md's table)."""
    table = report["variants"]
    assert isinstance(table, dict)
    battery = "battery_energy" in report
    lines = [
        "| plant | design | DC-bus energy [J] | vs predicted | vs 5 ms grid | TCP error rms / max [mm] "
        "| peak currents [A] | peak voltages [V] | optimal cheaper |"
        + (" battery energy [J] | vs predicted | optimal cheaper at the battery |" if battery else ""),
        "|---|---|---:|---:|---:|---:|---:|---:|---|" + ("---:|---:|---|" if battery else ""),
    ]
    for name, entry in table.items():
        for design in ("initial", "optimal"):
            if design not in entry:
                continue
            row = entry[design]
            tcp = row["tcp_error_mm"]
            currents = " / ".join(f"{v:.1f}" for v in row["peak_current_A"].values())
            voltages = " / ".join(f"{v:.0f}" for v in row["peak_voltage_V"].values())
            cheaper = (
                {True: "yes", False: "**no**"}.get(entry.get("optimal_below_initial"), "")
                if design == "optimal"
                else ""
            )
            fine = row.get("energy_difference_to_5ms_grid_percent")
            line = (
                f"| {name} | {design} | {row['dc_bus_energy_J']:.1f} "
                f"| {row['dc_bus_energy_difference_percent']:+.2f} % "
                f"| {'' if fine is None else format(fine, '+.2f') + ' %'} "
                f"| {tcp['rms']:.2f} / {tcp['max']:.2f} | {currents} | {voltages} | {cheaper} |"
            )
            if battery:
                difference = row["battery_energy_difference_percent"]
                at_battery = (
                    {True: "yes", False: "**no**"}.get(entry.get("optimal_below_initial_battery"), "")
                    if design == "optimal"
                    else ""
                )
                versus = "" if difference is None else format(difference, "+.2f") + " %"
                line += f" {row['battery_energy_J']:.1f} | {versus} | {at_battery} |"
            lines.append(line)
    return "\n".join(lines)


def compact_effect_table(report: dict[str, object]) -> str:
    """Five-line markdown table of the effect study: one column per variant, both designs in each cell.

    Rows: the closed loop's battery energy against the prediction [%] (the DC-bus energy where the result
    has no battery), the TCP's largest error [mm], and whether the optimal design draws less than the
    initial one in closed loop (at the battery, or at the DC bus).
    """
    table = report["variants"]
    assert isinstance(table, dict)
    battery = "battery_energy" in report
    designs = [d for d in ("initial", "optimal") if all(d in entry for entry in table.values())]
    names = list(table)
    key, where = (
        ("battery_energy_difference_percent", "battery energy")
        if battery
        else ("dc_bus_energy_difference_percent", "DC-bus energy")
    )
    cheaper_key = "optimal_below_initial_battery" if battery else "optimal_below_initial"

    def cells(value: Any) -> str:
        return " | ".join(value(table[name]) for name in names)

    def percent(entry: dict[str, Any]) -> str:
        values = [entry[d][key] for d in designs]
        if any(v is None for v in values):
            return "n/a"
        return " / ".join(f"{v:+.2f}" for v in values) + " %"

    def tcp(entry: dict[str, Any]) -> str:
        return " / ".join(f"{entry[d]['tcp_error_mm']['max']:.2f}" for d in designs)

    def cheaper(entry: dict[str, Any]) -> str:
        flag = entry.get(cheaper_key)
        return "n/a" if flag is None else ("yes" if flag else "**no**")

    label = " / ".join(designs)
    lines = [
        f"| effect | {' | '.join(names)} |",
        "|---|" + "---:|" * len(names),
        f"| closed-loop {where} vs predicted ({label}) | {cells(percent)} |",
        f"| TCP max error ({label}) [mm] | {cells(tcp)} |",
    ]
    if designs == ["initial", "optimal"]:
        at = "at the battery" if battery else "at the DC bus"
        lines.append(f"| optimum stays cheaper ({at}) | {cells(cheaper)} |")
    return "\n".join(lines)


def effect_markdown(report: dict[str, object]) -> str:
    """``effects.md``: the compact table (:func:`compact_effect_table`), the full table, the lines in words."""
    cycles = report.get("cycles", 1)
    task = f", task {report['task']} (its own plans and energies)" if report.get("task") else ""
    parts = [
        f"# Plant effects: {report['plant']} plant{task}, {cycles} cycle(s) per run (energies of the last)",
        "",
        compact_effect_table(report),
        "",
        effect_table(report),
        "",
        *(f"* {line}" for line in effect_lines(report)),
        "",
    ]
    return "\n".join(parts)


def write_effect_markdown(path: Path, report: dict[str, object]) -> Path:
    """Write :func:`effect_markdown` to ``path`` (``effects.md`` in the run folder); return the path."""
    from hiab_sim.atomic_io import write_atomic

    write_atomic(path, effect_markdown(report))
    return path


def effect_lines(report: dict[str, object]) -> list[str]:
    """The effect study in words: each effect's share of the energy difference, the mismatch's split and re-plan."""
    lines = []
    for key, what in (("share_of_energy_difference", "DC-bus"), ("share_of_battery_energy_difference", "battery")):
        shares = report.get(key)
        if not isinstance(shares, dict):
            continue
        for design, row in shares.items():
            parts = ", ".join(f"{name} {100 * share:+.0f} %" for name, share in row.items())
            lines.append(f"{design}: share of the all-effects {what} energy difference to the ideal plant: {parts}.")
    split = report.get("mismatch_split")
    if isinstance(split, dict):
        for design, row in split.items():
            text = (
                f"{design}, mismatch: predicted {row['predicted_J']:.1f} J, at the true masses "
                f"{row['predicted_at_true_masses_J']:.1f} J, closed loop {row['closed_loop_J']:.1f} J"
            )
            if "replanned_optimum_predicted_J" in row:
                replanned = row["replanned_optimum_predicted_J"]
                if report.get("task") is None:
                    text += f"; the study re-planned for the true masses predicts {replanned:.1f} J"
                else:
                    text += (
                        "; the mix re-planned for the true masses (one solve for all its tasks) predicts "
                        f"{replanned:.1f} J on this task"
                    )
            text += " (net electrical energy)"
            if "closed_loop_battery_J" in row:
                text += (
                    f"; at the battery: predicted {row['predicted_battery_J']:.1f} J, closed loop "
                    f"{row['closed_loop_battery_J']:.1f} J"
                )
                if "replanned_optimum_predicted_battery_J" in row:
                    text += f", re-planned {row['replanned_optimum_predicted_battery_J']:.1f} J"
            lines.append(text + ".")
    return lines


#: Each variant of the effect study in words (the figure's tick labels; the plant file's keys in the tables).
EFFECT_WORDS = {
    "ideal": "ideal plant",
    "drive_train": "drive-train\ncompliance, backlash",
    "joint_friction": "hinge and pin\nfriction",
    "sensors": "sensor noise,\nresolution, delay",
    "current_loop": "discrete current\nloop, dead time",
    "thermal": "windings heating\nover cycles",
    "mismatch": "mass and friction\nerrors",
    "all": "all effects",
}


def effect_figure(path: Path, report: dict[str, object]) -> Path:
    """Bar chart: the closed loop's energy against the prediction per variant and design [%].

    At the battery where the run has a battery model (one boundary with the planner's answer), else at
    the DC bus; the variants in words (:data:`EFFECT_WORDS`).
    """
    table = report["variants"]
    assert isinstance(table, dict)
    names = list(table)
    battery = "battery_energy" in report
    key = "battery_energy_difference_percent" if battery else "dc_bus_energy_difference_percent"
    where = "battery energy" if battery else "DC-bus energy (drives' input)"
    fig = new_figure((9.0, 3.9))
    ax = fig.add_subplot()
    x = np.arange(len(names))
    for offset, design in ((-0.2, "initial"), (0.2, "optimal")):
        values = [
            np.nan if design not in table[n] or table[n][design].get(key) is None else table[n][design][key]
            for n in names
        ]
        ax.bar(x + offset, values, width=0.4, color=COLOURS.get(design, COLOURS["reference"]), label=f"{design} design")
    ax.set_xticks(x, [EFFECT_WORDS.get(n, n.replace("_", " ")) for n in names], fontsize=8)
    ax.axhline(0.0, color="k", linewidth=0.8)
    ax.set(
        ylabel="closed loop vs predicted [%]",
        title=f"Closed-loop {where} against the plan's prediction, per plant effect ({report['plant']} plant)",
    )
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    return save_png(fig, path, 110)

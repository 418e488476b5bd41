"""Side-by-side comparison of result folders: one table row per run and design, and a figure.

Columns (SI units scaled for reading): every run's decision variables by name (``chain variable``)
[mm]; net electrical energy, energy drawn (positive part of the summed power) and battery energy
[kJ] on the fine grid; peak force [kN] and peak electrical power [kW] of every actuator by name;
the smallest EMLA envelope margin over the actuators (fraction of the limit); the design's max
constraint violation (scaled); and the saving of net energy against the same run's initial design
[%]. Runs of different machines share a table: a column another machine lacks holds NaN. Energies
of runs with different tasks (reference, payload) are not comparable with each other, only with
their own initial design.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from hiab_sim.atomic_io import write_atomic
from hiab_sim.results.read import DESIGNS, RunSummary
from hiab_sim.style import colour

#: Columns after the design variables and before the per-actuator peaks: header -> unit.
_ENERGY_COLUMNS: tuple[tuple[str, str], ...] = (
    ("net energy", "kJ"),
    ("drawn energy", "kJ"),
    ("battery energy", "kJ"),
)
#: Columns after the per-actuator peaks.
_LAST_COLUMNS: tuple[tuple[str, str], ...] = (
    ("min envelope margin", "1"),
    ("max violation", "1"),
    ("saving vs initial", "%"),
)


def variable_names(runs: Sequence[RunSummary]) -> list[str]:
    """The decision variables of every run, in order of first appearance (``chain.variable``)."""
    out: list[str] = []
    for run in runs:
        out += [name for name in run.design_names if name not in out]
    return out


def actuator_names(runs: Sequence[RunSummary]) -> list[str]:
    """The actuators of every run, in order of first appearance."""
    out: list[str] = []
    for run in runs:
        out += [name for name in run.actuators if name not in out]
    return out


def columns(runs: Sequence[RunSummary]) -> list[tuple[str, str]]:
    """Column header -> unit, in table order, for these runs (their variables and actuators by name)."""
    cols = [("run", ""), ("design", "")]
    cols += [(name.replace(".", " "), "mm") for name in variable_names(runs)]
    cols += list(_ENERGY_COLUMNS)
    actuators = actuator_names(runs)
    cols += [(f"{a} peak force", "kN") for a in actuators] + [(f"{a} peak power", "kW") for a in actuators]
    return cols + list(_LAST_COLUMNS)


@dataclass(frozen=True)
class Row:
    """One row of the comparison: a run's design and its numbers by column header (units of :func:`columns`).

    A run lacking a column's variable or actuator (another machine's) has NaN there.
    """

    run: str
    design: str
    values: dict[str, float]


def rows(runs: Sequence[RunSummary]) -> list[Row]:
    """Table rows: for each run its initial then its optimal design."""
    out = []
    variables, actuators = variable_names(runs), actuator_names(runs)
    for run in runs:
        initial = run.designs["initial"].net_energy_J
        for name in DESIGNS:
            d = run.designs[name]
            given = dict(zip(run.design_names, (float(v) for v in d.lengths.as_array()), strict=True))
            values = {v.replace(".", " "): 1e3 * given.get(v, math.nan) for v in variables}
            values["net energy"] = d.net_energy_J / 1e3
            values["drawn energy"] = d.drawn_energy_J / 1e3
            values["battery energy"] = math.nan if d.battery_energy_J is None else d.battery_energy_J / 1e3
            values.update({f"{a} peak force": d.peak_force_N.get(a, math.nan) / 1e3 for a in actuators})
            values.update({f"{a} peak power": d.peak_power_W.get(a, math.nan) / 1e3 for a in actuators})
            values["min envelope margin"] = min(d.min_envelope_margin.values())
            values["max violation"] = d.max_violation
            values["saving vs initial"] = 100.0 * (1.0 - d.net_energy_J / initial)
            out.append(Row(run.name, name, values))
    return out


def _format(unit: str, name: str) -> str:
    return {"mm": "{:.1f}", "kJ": "{:.3f}", "kN": "{:.2f}", "kW": "{:.2f}", "%": "{:.2f}"}.get(
        unit, "{:.1e}" if name == "max violation" else "{:.3f}"
    )


def header(cols: Sequence[tuple[str, str]]) -> list[str]:
    """Column titles with units."""
    return [f"{name} [{unit}]" if unit else name for name, unit in cols]


def format_table(table: Sequence[Row], cols: Sequence[tuple[str, str]]) -> str:
    """A fixed-width text table (one line per row, header first)."""
    cells = [header(cols)] + [
        [r.run, r.design, *(_format(u, n).format(r.values[n]) for n, u in cols[2:])] for r in table
    ]
    widths = [max(len(row[i]) for row in cells) for i in range(len(cols))]
    lines = ["  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(row, widths, strict=True)))
             for row in cells]  # fmt: skip
    return "\n".join(lines) + "\n"


def to_csv(table: Sequence[Row], cols: Sequence[tuple[str, str]]) -> str:
    """The table as CSV with full precision (header with units)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header(cols))
    for r in table:
        writer.writerow([r.run, r.design, *(repr(float(r.values[n])) for n, _ in cols[2:])])
    return buffer.getvalue()


def write_comparison(out: Path, runs: Sequence[RunSummary]) -> list[Path]:
    """Write ``comparison.csv``, ``comparison.txt`` and ``comparison.png`` into ``out`` atomically."""
    table, cols = rows(runs), columns(runs)
    paths = [out / "comparison.csv", out / "comparison.txt", out / "comparison.png"]
    write_atomic(paths[0], to_csv(table, cols))
    write_atomic(paths[1], format_table(table, cols))
    write_atomic(paths[2], comparison_figure(runs))
    return paths


def comparison_figure(runs: Sequence[RunSummary]) -> bytes:
    """PNG: net energy of each run's designs (bars with numbers) and the change of each length [mm]."""
    import numpy as np

    from hiab_sim.figure_io import new_figure, png_bytes

    fig = new_figure((11.0, 4.2))
    energy_ax, length_ax = fig.subplots(1, 2, width_ratios=(1.0, 1.4))
    x = np.arange(len(runs))
    width = 0.38
    for k, name in enumerate(DESIGNS):
        values = [run.designs[name].net_energy_J / 1e3 for run in runs]
        bars = energy_ax.bar(x + (k - 0.5) * width, values, width, color=colour(name), label=name)
        energy_ax.bar_label(bars, fmt="%.3f", fontsize=8)
    for i, run in enumerate(runs):
        energy_ax.annotate(
            f"-{run.saved_percent:.2f} %", (x[i] + 0.5 * width, 0.5 * run.designs["optimal"].net_energy_J / 1e3),
            ha="center", color="white", fontsize=9, weight="bold",
        )  # fmt: skip
    energy_ax.set_xticks(x, [run.name for run in runs], rotation=15)
    energy_ax.set_ylabel("net electrical energy [kJ]")
    energy_ax.set_title("energy per run (saving vs its initial design)")
    energy_ax.legend(loc="lower right")
    variables = variable_names(runs)
    labels = [v.replace(".", " ") for v in variables]
    pos = np.arange(len(labels))
    step = 0.8 / max(len(runs), 1)
    for i, run in enumerate(runs):
        moved = dict(
            zip(
                run.design_names,
                run.designs["optimal"].lengths.as_array() - run.designs["initial"].lengths.as_array(),
                strict=True,
            )
        )
        change = np.array([1e3 * moved.get(v, np.nan) for v in variables])
        bars = length_ax.bar(pos - 0.4 + (i + 0.5) * step, change, step, color=colour("optimal"),
                             alpha=1.0 - 0.6 * i / max(len(runs), 1), edgecolor="black", linewidth=0.5, label=run.name,
                             hatch=("", "//", "..", "xx", "\\\\")[i % 5])  # fmt: skip
        length_ax.bar_label(bars, fmt="%+.0f", fontsize=7)
    length_ax.axhline(0.0, color="0.3", linewidth=0.6)
    length_ax.set_xticks(pos, labels)
    length_ax.set_ylabel("optimal - initial [mm]")
    length_ax.set_title("change of each decision variable")
    length_ax.legend(fontsize=8)
    return png_bytes(fig)

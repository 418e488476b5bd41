"""Side-by-side comparison of result folders: one table row per run and design, and a figure.

Columns (SI units scaled for reading), named by each run's machine: its decision variables
(``<chain> <variable>`` [mm]); net electrical energy and drawn energy without regeneration [kJ] on
the fine grid; peak actuator force [kN] and peak electrical power [kW] of each actuator whose
mounting the decision variables move; the smallest EMLA envelope margin over all actuators
(fraction of the limit); the design's max constraint violation (scaled); and the saving of net
energy against the same run's initial design [%]. Runs of different machines share the columns
they have in common; a column a run lacks is NaN (``n/a``). Energies of runs with different
tasks (reference, payload) are not comparable with each other, only with their own initial design.
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

#: Columns after the decision variables and before the peaks: name -> (unit, format).
_ENERGIES = {"net energy": ("kJ", "{:.3f}"), "drawn energy": ("kJ", "{:.3f}"), "battery energy": ("kJ", "{:.3f}")}
#: The last columns: name -> (unit, format).
_CHECKS = {
    "min envelope margin": ("1", "{:.3f}"),
    "max violation": ("1", "{:.1e}"),
    "saving vs initial": ("%", "{:.2f}"),
}


@dataclass(frozen=True)
class Row:
    """One row of the comparison: a run's design and its numbers by column name, in the units of :func:`columns`."""

    run: str
    design: str
    values: dict[str, float]


def _label(variable: str) -> str:
    """``chain.variable`` as a column name: ``chain variable``."""
    return variable.replace(".", " ", 1)


def columns(runs: Sequence[RunSummary]) -> dict[str, tuple[str, str]]:
    """Column name -> (unit, format) after run and design, in table order, over every run's machine."""
    out: dict[str, tuple[str, str]] = {}
    for run in runs:
        out |= {_label(v): ("mm", "{:.1f}") for v in run.variables if _label(v) not in out}
    out |= _ENERGIES
    for quantity, unit in (("peak force", "kN"), ("peak power", "kW")):
        for run in runs:
            out |= {f"{a} {quantity}": (unit, "{:.2f}") for a in run.mounted if f"{a} {quantity}" not in out}
    return out | _CHECKS


def rows(runs: Sequence[RunSummary]) -> list[Row]:
    """Table rows: for each run its initial then its optimal design."""
    out = []
    for run in runs:
        initial = run.designs["initial"].net_energy_J
        for name in DESIGNS:
            d = run.designs[name]
            values = {_label(v): 1e3 * x for v, x in zip(run.variables, d.lengths.as_array(), strict=True)}
            values |= {
                "net energy": d.net_energy_J / 1e3,
                "drawn energy": d.drawn_energy_J / 1e3,
                "battery energy": math.nan if d.battery_energy_J is None else d.battery_energy_J / 1e3,
            }
            values |= {f"{a} peak force": d.peak_force_N[a] / 1e3 for a in run.mounted}
            values |= {f"{a} peak power": d.peak_power_W[a] / 1e3 for a in run.mounted}
            values |= {
                "min envelope margin": min(d.min_envelope_margin.values()),
                "max violation": d.max_violation,
                "saving vs initial": 100.0 * (1.0 - d.net_energy_J / initial),
            }
            out.append(Row(run.name, name, values))
    return out


def header(spec: dict[str, tuple[str, str]]) -> list[str]:
    """Column titles with units: run, design and the ``spec`` of :func:`columns`."""
    return ["run", "design", *(f"{name} [{unit}]" for name, (unit, _) in spec.items())]


def format_table(runs: Sequence[RunSummary]) -> str:
    """A fixed-width text table (one line per row, header first)."""
    spec = columns(runs)
    cells = [header(spec)] + [
        [r.run, r.design, *("n/a" if math.isnan(v := r.values.get(c, math.nan)) else f.format(v)
                            for c, (_, f) in spec.items())]
        for r in rows(runs)
    ]  # fmt: skip
    widths = [max(len(row[i]) for row in cells) for i in range(len(cells[0]))]
    lines = ["  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(row, widths, strict=True)))
             for row in cells]  # fmt: skip
    return "\n".join(lines) + "\n"


def to_csv(runs: Sequence[RunSummary]) -> str:
    """The table as CSV with full precision (header with units)."""
    spec = columns(runs)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header(spec))
    for r in rows(runs):
        writer.writerow([r.run, r.design, *(repr(float(r.values.get(c, math.nan))) for c in spec)])
    return buffer.getvalue()


def write_comparison(out: Path, runs: Sequence[RunSummary]) -> list[Path]:
    """Write ``comparison.csv``, ``comparison.txt`` and ``comparison.png`` into ``out`` atomically."""
    paths = [out / "comparison.csv", out / "comparison.txt", out / "comparison.png"]
    write_atomic(paths[0], to_csv(runs))
    write_atomic(paths[1], format_table(runs))
    write_atomic(paths[2], comparison_figure(runs))
    return paths


def comparison_figure(runs: Sequence[RunSummary]) -> bytes:
    """PNG: net energy of each run's designs (bars with numbers) and the change of each decision variable [mm]."""
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
    labels = list(dict.fromkeys(_label(v) for run in runs for v in run.variables))
    step = 0.8 / max(len(runs), 1)
    for i, run in enumerate(runs):
        change = 1e3 * (run.designs["optimal"].lengths.as_array() - run.designs["initial"].lengths.as_array())
        pos = np.array([labels.index(_label(v)) for v in run.variables], dtype=float)
        bars = length_ax.bar(pos - 0.4 + (i + 0.5) * step, change, step, color=colour("optimal"),
                             alpha=1.0 - 0.6 * i / max(len(runs), 1), edgecolor="black", linewidth=0.5, label=run.name,
                             hatch=("", "//", "..", "xx", "\\\\")[i % 5])  # fmt: skip
        length_ax.bar_label(bars, fmt="%+.0f", fontsize=7)
    length_ax.axhline(0.0, color="0.3", linewidth=0.6)
    length_ax.set_xticks(np.arange(len(labels)), labels, rotation=15 if len(labels) > 6 else 0)
    length_ax.set_ylabel("optimal - initial [mm]")
    length_ax.set_title("change of each decision variable")
    length_ax.legend(fontsize=8)
    return png_bytes(fig)

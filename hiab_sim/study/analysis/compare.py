"""Side-by-side comparison of result folders: one table row per run and design, and a figure.

Columns (SI units scaled for reading): the six link lengths [mm]; net electrical energy and
drawn energy without regeneration [kJ] on the fine grid; peak actuator force [kN] and peak
electrical power [kW] of lift and tilt; the smallest EMLA envelope margin over the three
actuators (fraction of the limit); the design's max constraint violation (scaled); and the saving
of net energy against the same run's initial design [%]. Energies of runs with different tasks
(reference, payload) are not comparable with each other, only with their own initial design.
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

#: Column header -> unit, in table order.
COLUMNS: tuple[tuple[str, str], ...] = (
    ("run", ""),
    ("design", ""),
    ("lift L", "mm"),
    ("lift Lc0", "mm"),
    ("lift Lc", "mm"),
    ("tilt L", "mm"),
    ("tilt Lc0", "mm"),
    ("tilt Lc", "mm"),
    ("net energy", "kJ"),
    ("drawn energy", "kJ"),
    ("battery energy", "kJ"),
    ("lift peak force", "kN"),
    ("tilt peak force", "kN"),
    ("lift peak power", "kW"),
    ("tilt peak power", "kW"),
    ("min envelope margin", "1"),
    ("max violation", "1"),
    ("saving vs initial", "%"),
)


@dataclass(frozen=True)
class Row:
    """One row of the comparison: a run's design and its numbers, in :data:`COLUMNS` order."""

    run: str
    design: str
    values: tuple[float, ...]  # every column after run and design, in the units of COLUMNS


def rows(runs: Sequence[RunSummary]) -> list[Row]:
    """Table rows: for each run its initial then its optimal design."""
    out = []
    for run in runs:
        initial = run.designs["initial"].net_energy_J
        for name in DESIGNS:
            d = run.designs[name]
            values = (
                *(1e3 * v for v in d.lengths.as_array()),
                d.net_energy_J / 1e3,
                d.drawn_energy_J / 1e3,
                math.nan if d.battery_energy_J is None else d.battery_energy_J / 1e3,
                d.peak_force_N["lift"] / 1e3,
                d.peak_force_N["tilt"] / 1e3,
                d.peak_power_W["lift"] / 1e3,
                d.peak_power_W["tilt"] / 1e3,
                min(d.min_envelope_margin.values()),
                d.max_violation,
                100.0 * (1.0 - d.net_energy_J / initial),
            )
            out.append(Row(run.name, name, values))
    return out


_FORMATS = ("{:.1f}",) * 6 + ("{:.3f}",) * 3 + ("{:.2f}",) * 4 + ("{:.3f}", "{:.1e}", "{:.2f}")


def header() -> list[str]:
    """Column titles with units."""
    return [f"{name} [{unit}]" if unit else name for name, unit in COLUMNS]


def format_table(table: Sequence[Row]) -> str:
    """A fixed-width text table (one line per row, header first)."""
    cells = [header()] + [
        [r.run, r.design, *(f.format(v) for f, v in zip(_FORMATS, r.values, strict=True))] for r in table
    ]
    widths = [max(len(row[i]) for row in cells) for i in range(len(COLUMNS))]
    lines = ["  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(row, widths, strict=True)))
             for row in cells]  # fmt: skip
    return "\n".join(lines) + "\n"


def to_csv(table: Sequence[Row]) -> str:
    """The table as CSV with full precision (header with units)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header())
    for r in table:
        writer.writerow([r.run, r.design, *(repr(float(v)) for v in r.values)])
    return buffer.getvalue()


def write_comparison(out: Path, runs: Sequence[RunSummary]) -> list[Path]:
    """Write ``comparison.csv``, ``comparison.txt`` and ``comparison.png`` into ``out`` atomically."""
    table = rows(runs)
    paths = [out / "comparison.csv", out / "comparison.txt", out / "comparison.png"]
    write_atomic(paths[0], to_csv(table))
    write_atomic(paths[1], format_table(table))
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
    labels = ["lift L", "lift Lc0", "lift Lc", "tilt L", "tilt Lc0", "tilt Lc"]
    pos = np.arange(len(labels))
    step = 0.8 / max(len(runs), 1)
    for i, run in enumerate(runs):
        change = 1e3 * (run.designs["optimal"].lengths.as_array() - run.designs["initial"].lengths.as_array())
        bars = length_ax.bar(pos - 0.4 + (i + 0.5) * step, change, step, color=colour("optimal"),
                             alpha=1.0 - 0.6 * i / max(len(runs), 1), edgecolor="black", linewidth=0.5, label=run.name,
                             hatch=("", "//", "..", "xx", "\\\\")[i % 5])  # fmt: skip
        length_ax.bar_label(bars, fmt="%+.0f", fontsize=7)
    length_ax.axhline(0.0, color="0.3", linewidth=0.6)
    length_ax.set_xticks(pos, labels)
    length_ax.set_ylabel("optimal - initial [mm]")
    length_ax.set_title("change of each link length")
    length_ax.legend(fontsize=8)
    return png_bytes(fig)

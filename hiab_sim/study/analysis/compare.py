"""Side-by-side comparison of result folders: one table row per run and design, and a figure.

Each run is labelled by its folder's name (:func:`run_labels`; the parent folders are added where two
names coincide), not by its study's name: two runs of one study are two folders. Columns (SI units
scaled for reading), named by each run's machine: its decision variables (``<chain> <variable>``
[mm]); the energies on the fine grid, each named by its boundary [kJ]: the net electrical energy at
the drives (the motor terminals' power summed over the drives, regeneration credited), the energy
drawn at the drives (the positive part of that summed power) and the battery energy at the battery
(through the inverters, the shared DC bus and the battery's efficiencies); peak actuator force [kN]
and peak electrical power [kW] of each actuator whose mounting the decision variables move; the
smallest EMLA envelope margin over all actuators (fraction of the limit); the design's max
constraint violation (scaled); and the saving against the same run's initial design [%] of both
energies. The run's objective declares the energy its saving is read from (:func:`saved_energy`,
the objective's ``measured_by`` in :mod:`hiab_sim.study.nlp.objectives`): the battery energy for
``battery_energy``; the net electrical energy for ``costf2`` (a squared power, not an energy, whose
paper reports that saving), for an objective not registered in this process and for a result
without a battery model. Runs of
different machines share the columns they have in common; a column a run lacks is NaN (``n/a``).
Energies of runs with different tasks (reference, payload) are not comparable with each other, only
with their own initial design.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from hiab_sim.atomic_io import write_atomic
from hiab_sim.percent import saving_percent
from hiab_sim.results.read import DESIGNS, RunSummary, summarise
from hiab_sim.study.nlp.objectives import measured_by
from hiab_sim.style import colour

#: The energies by boundary: column name -> the :class:`~hiab_sim.results.read.DesignSummary` field [J].
NET = "net electrical energy at the drives"
DRAWN = "drawn energy at the drives"
BATTERY = "battery energy at the battery"
#: The saving of each energy against the run's initial design, by that energy's column.
SAVING = {NET: "net electrical energy saving vs initial", BATTERY: "battery energy saving vs initial"}
#: The column of each energy an objective's ``measured_by`` names (objectives.RESULT_ENERGIES).
MEASURED = {"net_electrical_energy": NET, "battery_energy": BATTERY}
#: Columns after the decision variables and before the peaks: name -> (unit, format).
_ENERGIES = {NET: ("kJ", "{:.3f}"), DRAWN: ("kJ", "{:.3f}"), BATTERY: ("kJ", "{:.3f}")}
#: The last columns: name -> (unit, format).
_CHECKS = {
    "min envelope margin": ("1", "{:.3f}"),
    "max violation": ("1", "{:.1e}"),
    SAVING[NET]: ("%", "{:.2f}"),
    SAVING[BATTERY]: ("%", "{:.2f}"),
}


@dataclass(frozen=True)
class ComparedRun:
    """One result folder in the comparison: its label, its summary and the energy its saving is read from."""

    label: str  # the folder's name, distinct among the runs compared (:func:`run_labels`)
    summary: RunSummary
    saved: str  # the energy whose saving answers the run's objective, :data:`BATTERY` or :data:`NET` (saved_energy)

    @property
    def objective(self) -> str:
        """The study's objective (``result.json`` energy.objective; costf2 without an energy section)."""
        return self.summary.objective


def saved_energy(run: RunSummary) -> str:
    """The column of the energy that measures the run's objective (its ``measured_by``), :data:`NET` where none does.

    :data:`NET` also where the objective is not registered in this process or the result lacks that
    energy (a battery energy without the result's battery model).
    """
    energy = measured_by(run.objective)
    column = NET if energy is None else MEASURED[energy]
    has_battery = all(run.designs[name].battery_energy_J is not None for name in DESIGNS)
    return BATTERY if column == BATTERY and has_battery else NET


def run_labels(folders: Sequence[str | Path]) -> list[str]:
    """Each folder's name, with as many parent folders as it takes to tell it from the others' (``a/run``, ``b/run``).

    The same folder given twice is labelled ``<name> (2)`` the second time.
    """
    paths = [Path(folder).resolve() for folder in folders]
    parts = [p.relative_to(p.anchor).parts or (p.anchor,) for p in paths]  # without the root: "/a/run" is a, run
    depth = [1] * len(parts)
    while True:
        labels = ["/".join(p[-d:]) for p, d in zip(parts, depth, strict=True)]
        clash = [
            k
            for k, label in enumerate(labels)
            if depth[k] < len(parts[k]) and any(labels[j] == label and paths[j] != paths[k] for j in range(len(parts)))
        ]
        if not clash:
            break
        for k in clash:
            depth[k] += 1
    seen: dict[str, int] = {}
    out = []
    for label in labels:
        seen[label] = seen.get(label, 0) + 1
        out.append(label if seen[label] == 1 else f"{label} ({seen[label]})")
    return out


def read_runs(folders: Sequence[str | Path]) -> list[ComparedRun]:
    """Every folder's summary (its result read once), labelled (:func:`run_labels`), with its saved energy.

    A bad folder raises before any is used.
    """
    summaries = [summarise(folder) for folder in folders]
    return [
        ComparedRun(label, summary, saved_energy(summary))
        for label, summary in zip(run_labels(folders), summaries, strict=True)
    ]


@dataclass(frozen=True)
class Row:
    """One row of the comparison: a run's label, design, objective and its numbers by column name (:func:`columns`).

    ``saved`` names the energy whose saving answers the run's objective (:data:`BATTERY` or :data:`NET`).
    """

    run: str
    design: str
    objective: str
    saved: str
    values: dict[str, float]

    @property
    def saving(self) -> float:
        """The saving of :attr:`saved` against the run's initial design [%]."""
        return self.values[SAVING[self.saved]]


def _label(variable: str) -> str:
    """``chain.variable`` as a column name: ``chain variable``."""
    return variable.replace(".", " ", 1)


def columns(runs: Sequence[ComparedRun]) -> dict[str, tuple[str, str]]:
    """Column name -> (unit, format) after run, design and objective, in table order, over every run's machine."""
    out: dict[str, tuple[str, str]] = {}
    for run in runs:
        out |= {_label(v): ("mm", "{:.1f}") for v in run.summary.variables if _label(v) not in out}
    out |= _ENERGIES
    for quantity, unit in (("peak force", "kN"), ("peak power", "kW")):
        for run in runs:
            out |= {f"{a} {quantity}": (unit, "{:.2f}") for a in run.summary.mounted if f"{a} {quantity}" not in out}
    return out | _CHECKS


def _saving(value: float | None, initial: float | None) -> float:
    """(initial - value) / |initial| [%]; NaN where the result has no such energy."""
    return math.nan if value is None or initial is None else saving_percent(initial, value)


def rows(runs: Sequence[ComparedRun]) -> list[Row]:
    """Table rows: for each run its initial then its optimal design."""
    out = []
    for run in runs:
        start = run.summary.designs["initial"]
        for name in DESIGNS:
            d = run.summary.designs[name]
            values = {_label(v): 1e3 * x for v, x in zip(run.summary.variables, d.lengths.as_array(), strict=True)}
            values |= {
                NET: d.net_energy_J / 1e3,
                DRAWN: d.drawn_energy_J / 1e3,
                BATTERY: math.nan if d.battery_energy_J is None else d.battery_energy_J / 1e3,
            }
            values |= {f"{a} peak force": d.peak_force_N[a] / 1e3 for a in run.summary.mounted}
            values |= {f"{a} peak power": d.peak_power_W[a] / 1e3 for a in run.summary.mounted}
            values |= {
                "min envelope margin": min(d.min_envelope_margin.values()),
                "max violation": d.max_violation,
                SAVING[NET]: _saving(d.net_energy_J, start.net_energy_J),
                SAVING[BATTERY]: _saving(d.battery_energy_J, start.battery_energy_J),
            }
            out.append(Row(run.label, name, run.objective, run.saved, values))
    return out


def header(spec: dict[str, tuple[str, str]]) -> list[str]:
    """Column titles with units: run, design, objective and the ``spec`` of :func:`columns`."""
    return ["run", "design", "objective", *(f"{name} [{unit}]" for name, (unit, _) in spec.items())]


def format_table(runs: Sequence[ComparedRun]) -> str:
    """A fixed-width text table (one line per row, header first)."""
    spec = columns(runs)
    cells = [header(spec)] + [
        [r.run, r.design, r.objective, *("n/a" if math.isnan(v := r.values.get(c, math.nan)) else f.format(v)
                                         for c, (_, f) in spec.items())]
        for r in rows(runs)
    ]  # fmt: skip
    widths = [max(len(row[i]) for row in cells) for i in range(len(cells[0]))]
    lines = ["  ".join(c.ljust(w) if i < 3 else c.rjust(w) for i, (c, w) in enumerate(zip(row, widths, strict=True)))
             for row in cells]  # fmt: skip
    return "\n".join(lines) + "\n"


def to_csv(runs: Sequence[ComparedRun]) -> str:
    """The table as CSV with full precision (header with units)."""
    spec = columns(runs)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header(spec))
    for r in rows(runs):
        writer.writerow([r.run, r.design, r.objective, *(repr(float(r.values.get(c, math.nan))) for c in spec)])
    return buffer.getvalue()


def write_comparison(out: Path, runs: Sequence[ComparedRun]) -> list[Path]:
    """Write ``comparison.csv``, ``comparison.txt`` and ``comparison.png`` into ``out`` atomically."""
    paths = [out / "comparison.csv", out / "comparison.txt", out / "comparison.png"]
    write_atomic(paths[0], to_csv(runs))
    write_atomic(paths[1], format_table(runs))
    write_atomic(paths[2], comparison_figure(runs))
    return paths


def _energy_J(run: ComparedRun, design: str) -> float:
    """The design's energy whose saving answers the run's objective [J]."""
    d = run.summary.designs[design]
    value = d.battery_energy_J if run.saved == BATTERY else d.net_energy_J
    assert value is not None  # saved_energy picks the battery energy only where every design has it
    return value


def comparison_figure(runs: Sequence[ComparedRun]) -> bytes:
    """PNG: the energy of each run's objective per design (bars, numbers, change) and each variable's change [mm]."""
    import numpy as np

    from hiab_sim.figure_io import new_figure, png_bytes

    fig = new_figure((11.0, 4.2))
    energy_ax, length_ax = fig.subplots(1, 2, width_ratios=(1.0, 1.4))
    x = np.arange(len(runs))
    width = 0.38
    for k, name in enumerate(DESIGNS):
        values = [_energy_J(run, name) / 1e3 for run in runs]
        bars = energy_ax.bar(x + (k - 0.5) * width, values, width, color=colour(name), label=name)
        energy_ax.bar_label(bars, fmt="%.3f", fontsize=8)
    for i, run in enumerate(runs):
        saving = saving_percent(_energy_J(run, "initial"), _energy_J(run, "optimal"))
        energy_ax.annotate(
            f"{-saving:+.2f} %", (x[i] + 0.5 * width, 0.5 * _energy_J(run, "optimal") / 1e3),
            ha="center", color="white", fontsize=9, weight="bold",
        )  # fmt: skip
    energy_ax.set_xticks(x, [f"{run.label}\n{run.saved.split(' at ')[0]}" for run in runs], rotation=15)
    saved = {run.saved for run in runs}
    energy_ax.set_ylabel(f"{saved.pop()} [kJ]" if len(saved) == 1 else "energy of each run's objective [kJ]")
    energy_ax.set_title("energy per run (change vs its initial design)")
    energy_ax.legend(loc="lower right")
    labels = list(dict.fromkeys(_label(v) for run in runs for v in run.summary.variables))
    step = 0.8 / max(len(runs), 1)
    for i, run in enumerate(runs):
        designs = run.summary.designs
        change = 1e3 * (designs["optimal"].lengths.as_array() - designs["initial"].lengths.as_array())
        pos = np.array([labels.index(_label(v)) for v in run.summary.variables], dtype=float)
        bars = length_ax.bar(pos - 0.4 + (i + 0.5) * step, change, step, color=colour("optimal"),
                             alpha=1.0 - 0.6 * i / max(len(runs), 1), edgecolor="black", linewidth=0.5,
                             label=run.label, hatch=("", "//", "..", "xx", "\\\\")[i % 5])  # fmt: skip
        length_ax.bar_label(bars, fmt="%+.0f", fontsize=7)
    length_ax.axhline(0.0, color="0.3", linewidth=0.6)
    length_ax.set_xticks(np.arange(len(labels)), labels, rotation=15 if len(labels) > 6 else 0)
    length_ax.set_ylabel("optimal - initial [mm]")
    length_ax.set_title("change of each decision variable")
    length_ax.legend(fontsize=8)
    return png_bytes(fig)

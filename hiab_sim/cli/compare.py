"""``hiab-sim compare RUN_DIR...``: a short table over several optimisation results, the details in files.

Prints a table that fits 100 columns: per run a line with its label (the folder's name, distinct
among the runs: :func:`hiab_sim.study.analysis.compare.run_labels`), its study and objective and the
energy its saving is of, then a row per design with the net electrical energy at the drives, the
battery energy at the battery, the smallest envelope margin, the largest constraint violation and
the saving of that energy against the run's own initial design; a legend line names each column's
energy and boundary. With ``--out DIR`` it also writes the full table (the decision variables, peaks,
both savings; see :mod:`hiab_sim.study.analysis.compare`) as ``comparison.csv`` and
``comparison.txt`` and the figure ``comparison.png``; without ``--out`` nothing is written. A folder
that is missing or holds no result exits 2 with one line.
"""

from __future__ import annotations

import argparse
import math
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from hiab_sim.errors import InvalidInputError

if TYPE_CHECKING:
    from hiab_sim.study.analysis.compare import ComparedRun, Row

#: Widest console line of the table's rows and header [characters] (a run's label line is as long as its name).
CONSOLE_WIDTH = 100
#: Short table: (title, column of Row.values or None for the row's own saving, format).
_SHORT: tuple[tuple[str, str | None, str], ...] = (
    ("net at drives [kJ]", "net electrical energy at the drives", "{:.3f}"),
    ("battery [kJ]", "battery energy at the battery", "{:.3f}"),
    ("min envelope margin", "min envelope margin", "{:.3f}"),
    ("max violation", "max violation", "{:.1e}"),
    ("saving [%]", None, "{:+.2f}"),
)
#: What the short table's columns hold, printed under it.
LEGEND = (
    "net at drives: net electrical energy at the motor terminals, summed over the drives (regeneration credited); "
    "battery: energy the battery delivers (inverters, shared DC bus, battery efficiencies); saving: of the energy "
    "named on the run's line, against its own initial design"
)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "compare",
        help="compare optimisation results: a table of energies, margins and savings, and a figure",
        description=(
            "Compare result folders written by 'hiab-sim optimize', each labelled by its folder's name: for each "
            "run its initial and optimal design, their net electrical energy at the drives and battery energy at "
            "the battery, the smallest EMLA envelope margin (fraction of the motor's limit left), the largest "
            "constraint violation and the saving against the run's own initial design of the energy its objective "
            "declares (the battery energy for battery_energy, the net electrical energy for costf2). Energies of "
            "runs with different tasks are comparable only with their own initial design. --out DIR writes the "
            "full table (decision variables, peak forces and powers, both savings) and a figure."
        ),
    )
    parser.add_argument("runs", nargs="+", metavar="RUN_DIR", help="result folders (each with result.json)")
    parser.add_argument(
        "--out", metavar="DIR", help="also write comparison.csv, comparison.txt and comparison.png here (default: none)"
    )
    parser.set_defaults(run=run)


def short_table(runs: Sequence[ComparedRun], table: Sequence[Row]) -> str:
    """The console table: per run a line naming it, then one row per design of the :data:`_SHORT` columns."""
    titles = ["design", *(t for t, _, _ in _SHORT)]
    cells = [
        [f"  {r.design}", *(_cell(f, r.saving if key is None else r.values.get(key, math.nan)) for _, key, f in _SHORT)]
        for r in table
    ]
    widths = [max(len(row[k]) for row in [titles, *cells]) for k in range(len(titles))]

    def line(row: list[str]) -> str:
        return "  ".join([row[0].ljust(widths[0]), *(c.rjust(w) for c, w in zip(row[1:], widths[1:], strict=True))])

    lines = [line(titles)]
    for run in runs:
        lines.append(f"{run.label}: {run.summary.name}, objective {run.objective}, saving of its {run.saved}")
        lines += [line(c) for r, c in zip(table, cells, strict=True) if r.run == run.label]
    return "\n".join(lines) + "\n"


def _cell(form: str, value: float) -> str:
    return "n/a" if math.isnan(value) else form.format(value)


def run(args: argparse.Namespace) -> int:
    """Read every result, print the short table, write the files where --out says."""
    from hiab_sim.study.analysis.compare import read_runs, rows, write_comparison

    runs = read_runs(args.runs)  # every folder is read before anything is written
    table = rows(runs)
    print(short_table(runs, table), end="")
    print(textwrap.fill(LEGEND, CONSOLE_WIDTH))
    if args.out is None:
        print("full table (decision variables, peak forces and powers) and a figure: add --out DIR")
        return 0
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InvalidInputError("--out", str(out), "must be a folder (it is a file)")
    out.mkdir(parents=True, exist_ok=True)
    paths = write_comparison(out, runs)
    print(f"wrote {', '.join(p.name for p in paths)} into {out}")
    return 0

"""``hiab-sim compare RUN_DIR...``: a short table over several optimisation results, the details in files.

Prints a table that fits 100 columns (per run and design: net and battery energy, the smallest
envelope margin, the largest constraint violation and the saving against the run's own initial
design). With ``--out DIR`` it also writes the full table (the decision variables, peaks; see
:mod:`hiab_sim.study.analysis.compare`) as ``comparison.csv`` and ``comparison.txt`` and the figure
``comparison.png``; without ``--out`` nothing is written. A folder that is missing or holds no result
exits 2 with one line.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from hiab_sim.errors import InvalidInputError

if TYPE_CHECKING:
    from hiab_sim.study.analysis.compare import Row

#: Widest console line of the short table [characters].
CONSOLE_WIDTH = 100
#: Short table: (title, column of Row.values, format).
_SHORT = (
    ("net energy [kJ]", "net energy", "{:.3f}"),
    ("battery [kJ]", "battery energy", "{:.3f}"),
    ("min envelope margin", "min envelope margin", "{:.3f}"),
    ("max violation", "max violation", "{:.1e}"),
    ("saving [%]", "saving vs initial", "{:+.2f}"),
)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "compare",
        help="compare optimisation results: a table of energies, margins and savings, and a figure",
        description=(
            "Compare result folders written by 'hiab-sim optimize': for each run its initial and optimal design, "
            "their net electrical energy and battery energy, the smallest EMLA envelope margin (fraction of the "
            "motor's limit left), the largest constraint violation and the energy saved against the run's own "
            "initial design. Energies of runs with different tasks are comparable only with their own initial "
            "design. --out DIR writes the full table (decision variables, peak forces and powers) and a figure."
        ),
    )
    parser.add_argument("runs", nargs="+", metavar="RUN_DIR", help="result folders (each with result.json)")
    parser.add_argument(
        "--out", metavar="DIR", help="also write comparison.csv, comparison.txt and comparison.png here (default: none)"
    )
    parser.set_defaults(run=run)


def short_table(table: Sequence[Row], width: int = CONSOLE_WIDTH) -> str:
    """The console table: run, design and the :data:`_SHORT` columns, run names shortened to fit ``width``."""
    titles = ["design", *(t for t, _, _ in _SHORT)]
    cells = [[r.design, *(_cell(f, r.values.get(key, math.nan)) for _, key, f in _SHORT)] for r in table]
    widths = [max(len(row[k]) for row in [titles, *cells]) for k in range(len(titles))]
    room = width - sum(widths) - 2 * len(widths)
    names = [_shorten(r.run, room) for r in table]
    run_width = max(len("run"), *(len(n) for n in names))
    lines = []
    for name, row in zip(["run", *names], [titles, *cells], strict=True):
        parts = [name.ljust(run_width), row[0].ljust(widths[0])]
        parts += [c.rjust(w) for c, w in zip(row[1:], widths[1:], strict=True)]
        lines.append("  ".join(parts).rstrip())
    return "\n".join(lines) + "\n"


def _cell(form: str, value: float) -> str:
    return "n/a" if math.isnan(value) else form.format(value)


def _shorten(name: str, room: int) -> str:
    room = max(room, 8)
    return name if len(name) <= room else name[: room - 3] + "..."


def run(args: argparse.Namespace) -> int:
    """Read every result, print the short table, write the files where --out says."""
    from hiab_sim.results.read import summarise
    from hiab_sim.study.analysis.compare import rows, write_comparison

    runs = [summarise(folder) for folder in args.runs]  # every folder is read before anything is written
    table = rows(runs)
    print(short_table(table), end="")
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

"""``hiab-sim compare RUN_DIR...``: one table and one figure over several optimisation results.

Prints the table (lengths, energies, peaks, envelope margins, violations, savings; see
:mod:`hiab_sim.study.analysis.compare`) and writes ``comparison.csv``, ``comparison.txt`` and
``comparison.png`` into ``--out``. A folder that is missing or holds no result exits 2 with one line.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from hiab_sim.errors import InvalidInputError


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "compare",
        help="compare optimisation results: a table of lengths, energies, peaks, margins and savings, and a figure",
        description="Compare result folders written by 'hiab-sim optimize'.",
    )
    parser.add_argument("runs", nargs="+", metavar="RUN_DIR", help="result folders (each with result.json)")
    parser.add_argument("--out", default="comparison", metavar="DIR", help="output folder (default: comparison)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Read every result, print the table, write the files."""
    from hiab_sim.results.read import summarise
    from hiab_sim.study.analysis.compare import format_table, rows, write_comparison

    runs = [summarise(folder) for folder in args.runs]  # every folder is read before anything is written
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InvalidInputError("--out", str(out), "must be a folder (it is a file)")
    out.mkdir(parents=True, exist_ok=True)
    print(format_table(rows(runs)), end="")
    paths = write_comparison(out, runs)
    print(f"wrote {', '.join(str(p) for p in paths)}")
    return 0

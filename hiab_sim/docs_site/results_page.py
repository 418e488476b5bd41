"""The results pages: every generated block of ``docs/results/*.md`` rendered from the committed run data.

A page keeps its explaining prose by hand; each number from a run sits in a block between
``<!-- results:NAME:start -->`` and ``<!-- results:NAME:end -->`` that :data:`BLOCKS` ``[NAME]``
renders from ``docs/results/data/*.json`` (:mod:`hiab_sim.docs_site.results_data`). One command
re-runs the studies and regenerates everything (``scripts/results_pages.sh``); the steps are

    python -m hiab_sim.docs_site.results_page record RUN_DIR...   # run folders -> docs/results/data/<study>.json
    python -m hiab_sim.docs_site.results_page render [--check]     # data -> every block of every page

``render --check`` writes nothing and exits 1 when a page differs from what the data render (CI runs
it through ``tests/test_results_page.py``); whether the data are current is a separate check
(:func:`hiab_sim.docs_site.results_data.differences` against fresh runs, within its stated tolerances).
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Callable
from pathlib import Path

from hiab_sim.atomic_io import write_atomic
from hiab_sim.docs_site.results_data import (
    DATA_DIR,
    NotRecordedError,
    RunData,
    data_name,
    load_data,
    record,
    write_data,
)
from hiab_sim.docs_site.results_design_blocks import BLOCKS as DESIGN_BLOCKS
from hiab_sim.docs_site.results_energy_blocks import BLOCKS as ENERGY_BLOCKS
from hiab_sim.docs_site.results_machine_blocks import BLOCKS as MACHINE_BLOCKS
from hiab_sim.docs_site.results_space_blocks import BLOCKS as SPACE_BLOCKS

#: Every generated block by name: a function of the committed data that returns Markdown.
BLOCKS: dict[str, Callable[[RunData], str]] = {**DESIGN_BLOCKS, **ENERGY_BLOCKS, **MACHINE_BLOCKS, **SPACE_BLOCKS}
#: The results pages.
PAGES_DIR = DATA_DIR.parent
MARKER = re.compile(r"<!-- results:([a-z0-9-]+):start -->\n(.*?)<!-- results:\1:end -->", re.DOTALL)


def block_names(page: str) -> list[str]:
    """The names of a page's generated blocks, in order."""
    return [m.group(1) for m in MARKER.finditer(page)]


def render_block(name: str, runs: RunData) -> str:
    """One block's Markdown; a block whose study has no data yet says so (and which study) instead."""
    try:
        return BLOCKS[name](runs).strip()
    except NotRecordedError as missing:
        return (
            f"*Not recorded yet: `docs/results/data/{missing.study}.json` does not exist; "
            f"`scripts/results_pages.sh` runs `{missing.study}` and records it.*"
        )


def not_recorded(runs: RunData, pages_dir: Path | None = None) -> dict[str, str]:
    """The blocks of the pages that cannot render for want of a study's data: block name -> study."""
    out = {}
    for page in pages(pages_dir or PAGES_DIR):
        for name in block_names(page.read_text()):
            try:
                BLOCKS[name](runs)
            except NotRecordedError as missing:
                out[name] = missing.study
    return out


def render_page(page: str, runs: RunData) -> str:
    """The page with every generated block replaced by what :data:`BLOCKS` renders from ``runs``."""
    unknown = sorted(set(block_names(page)) - set(BLOCKS))
    if unknown:
        raise KeyError(f"no generator for the blocks {unknown}; known: {sorted(BLOCKS)}")
    opened = page.count("<!-- results:")
    if opened != 2 * len(block_names(page)):
        raise ValueError("every <!-- results:NAME:start --> needs its <!-- results:NAME:end --> on a line of its own")

    def fill(match: re.Match[str]) -> str:
        name = match.group(1)
        return f"<!-- results:{name}:start -->\n{render_block(name, runs)}\n<!-- results:{name}:end -->"

    return MARKER.sub(fill, page)


def pages(pages_dir: Path = PAGES_DIR) -> list[Path]:
    """The results pages that have generated blocks."""
    return [p for p in sorted(pages_dir.glob("*.md")) if block_names(p.read_text())]


def stale_pages(runs: RunData, pages_dir: Path = PAGES_DIR) -> list[Path]:
    """The pages whose text differs from what the data render."""
    return [p for p in pages(pages_dir) if render_page(p.read_text(), runs) != p.read_text()]


def main(argv: list[str] | None = None) -> int:
    """``record RUN_DIR...`` or ``render [--check]`` (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    rec = commands.add_parser("record", help="write docs/results/data/<study>.json from run folders")
    rec.add_argument("run_dirs", type=Path, nargs="+")
    ren = commands.add_parser("render", help="fill every generated block of docs/results/*.md from the data")
    ren.add_argument("--check", action="store_true", help="exit 1 when a page is stale; write nothing")
    for sub in (rec, ren):
        sub.add_argument("--data", type=Path, default=DATA_DIR, help="data folder (default: docs/results/data)")
    ren.add_argument("--pages", type=Path, default=PAGES_DIR, help="pages folder (default: docs/results)")
    args = parser.parse_args(argv)
    if args.command == "record":
        for run_dir in args.run_dirs:
            data = record(run_dir)
            print(f"recorded {write_data(data, data_name(data, run_dir), args.data)} from {run_dir}")
        return 0
    runs = RunData(load_data(args.data))
    if args.check:
        stale = stale_pages(runs, args.pages)
        for page in stale:
            print(f"results_page: {page} differs from what {args.data} renders (run: render)", file=sys.stderr)
        for name, study in not_recorded(runs, args.pages).items():
            print(f"results_page: block {name} waits for a recorded run of {study}", file=sys.stderr)
        return 1 if stale else 0
    for page in pages(args.pages):
        text = page.read_text()
        fresh = render_page(text, runs)
        if fresh != text:
            write_atomic(page, fresh)
            print(f"updated {page}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Replace the validation table in README.md with the one ``hiab-sim validate`` wrote.

Usage: ``python validate/update_readme.py [--table runs/validate/table.md] [--readme README.md] [--check]``,
from the repository root (the defaults are relative to the working folder, like ``hiab-sim validate --out``).
The table goes between the markers ``<!-- validation-table:start -->`` and
``<!-- validation-table:end -->``; with ``--check`` nothing is written and the exit status is 1
when the README is out of date.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from hiab_sim.atomic_io import write_atomic

START = "<!-- validation-table:start -->"
END = "<!-- validation-table:end -->"


def replace_block(readme: str, table: str) -> str:
    """README text with the block between the markers replaced by ``table``."""
    start, end = readme.find(START), readme.find(END)
    if start < 0 or end < 0 or end < start:
        raise ValueError(f"README must contain {START} followed by {END}")
    return readme[: start + len(START)] + "\n" + table.strip() + "\n" + readme[end:]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=Path("runs/validate/table.md"))
    parser.add_argument("--readme", type=Path, default=Path("README.md"))
    parser.add_argument("--check", action="store_true", help="only check that the README is up to date")
    args = parser.parse_args(argv)
    try:
        old = args.readme.read_text()
        new = replace_block(old, args.table.read_text())
    except (OSError, ValueError) as error:
        print(f"update_readme: {error}", file=sys.stderr)
        return 2
    if args.check:
        return 0 if new == old else 1
    write_atomic(args.readme, new)
    print(f"updated {args.readme} from {args.table}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

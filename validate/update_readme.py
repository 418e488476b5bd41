"""Replace the validation table of the documentation (docs/validation.md) with the one ``hiab-sim validate`` wrote.

Usage: ``python validate/update_readme.py [--table runs/validate/table.md] [--readme docs/validation.md] [--check]``,
from the repository root (the defaults are relative to the working folder, like ``hiab-sim validate --out``).
The table goes between the markers ``<!-- validation-table:start -->`` and
``<!-- validation-table:end -->``. With ``--check`` nothing is written and the exit status is 1
when the page is out of date (CI runs ``hiab-sim validate`` and then this check, see
scripts/test.sh): its text must equal the fresh table's except for the numbers written in
e-notation, which are round-off-level errors that change with the CPU and the BLAS build and
may differ by up to ``--round-off-factor`` (default 10; 0 on one side needs 0 on the other).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from hiab_sim.atomic_io import write_atomic

START = "<!-- validation-table:start -->"
END = "<!-- validation-table:end -->"
#: A number in e-notation as the table writes them (``{:.2e}``).
NUMBER = re.compile(r"[-+]?\d+\.\d+e[-+]\d+")


def current_block(readme: str) -> str:
    """The text between the markers (without the surrounding newlines)."""
    start, end = readme.find(START), readme.find(END)
    if start < 0 or end < 0 or end < start:
        raise ValueError(f"the page must contain {START} followed by {END}")
    return readme[start + len(START) : end].strip()


def _same_number(a: float, b: float, factor: float) -> bool:
    if a == b:
        return True
    if a == 0.0 or b == 0.0 or (a < 0.0) != (b < 0.0):
        return False
    return max(abs(a), abs(b)) <= factor * min(abs(a), abs(b))


def differences(written: str, fresh: str, factor: float) -> list[str]:
    """Where the page's table differs from a fresh one beyond round-off: one message per line that differs."""
    old_lines, new_lines = written.strip().splitlines(), fresh.strip().splitlines()
    if len(old_lines) != len(new_lines):
        return [f"the page's table has {len(old_lines)} lines, the fresh table {len(new_lines)}"]
    out = []
    for row, (old, new) in enumerate(zip(old_lines, new_lines, strict=True), start=1):
        old_numbers = [float(x) for x in NUMBER.findall(old)]
        new_numbers = [float(x) for x in NUMBER.findall(new)]
        same_text = NUMBER.sub("#", old) == NUMBER.sub("#", new)
        if not same_text or len(old_numbers) != len(new_numbers):
            out.append(f"line {row}: page {old!r} != fresh {new!r}")
            continue
        for a, b in zip(old_numbers, new_numbers, strict=True):
            if not _same_number(a, b, factor):
                out.append(f"line {row}: page {a:.2e} vs fresh {b:.2e} (more than x{factor:g} apart)")
    return out


def replace_block(readme: str, table: str) -> str:
    """The page's text with the block between the markers replaced by ``table``."""
    current_block(readme)  # the markers are there, in order
    start, end = readme.find(START), readme.find(END)
    return readme[: start + len(START)] + "\n" + table.strip() + "\n" + readme[end:]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, default=Path("runs/validate/table.md"))
    parser.add_argument(
        "--readme",
        "--page",
        dest="readme",
        type=Path,
        default=Path("docs/validation.md"),
        help="the page with the table",
    )
    parser.add_argument("--check", action="store_true", help="only check that the page is up to date")
    parser.add_argument(
        "--round-off-factor",
        type=float,
        default=10.0,
        help="with --check: how far apart (ratio) e-notation numbers may be (default 10)",
    )
    args = parser.parse_args(argv)
    try:
        old = args.readme.read_text()
        table = args.table.read_text()
        new = replace_block(old, table)
        stale = differences(current_block(old), table, args.round_off_factor)
    except (OSError, ValueError) as error:
        print(f"update_readme: {error}", file=sys.stderr)
        return 2
    if args.check:
        for line in stale[:10]:
            print(f"update_readme: {args.readme} is stale: {line}", file=sys.stderr)
        if stale:
            print("update_readme: run `hiab-sim validate` and `python validate/update_readme.py`", file=sys.stderr)
        return 1 if stale else 0
    write_atomic(args.readme, new)
    print(f"updated {args.readme} from {args.table}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Result pages generated from runs: the default study's numbers, written from its ``result.json`` and checked in CI.

``python -m hiab_sim.docs_site.results_page RUN_DIR [--page docs/results/default-study.md] [--check]``
replaces the block between ``<!-- results:start -->`` and ``<!-- results:end -->`` with the table
:func:`results_block` writes from the run; with ``--check`` nothing is written and the exit status is 1
when the page is stale: the text must be the same and every number within :data:`RELATIVE_TOLERANCE`
of the fresh one (or one unit of its last printed digit), since a re-run on another CPU moves the last
digits (SLSQP's stopping point moves with round-off). ``tests/test_default_study.py`` runs the check on
the default study it optimises.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from hiab_sim.atomic_io import write_atomic
from hiab_sim.crane.description import CHAIN_NAMES
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import Result

START, END = "<!-- results:start -->", "<!-- results:end -->"
#: How far a page's number may be from a fresh run's (relative), beyond one unit of its last digit.
RELATIVE_TOLERANCE = 2e-3
NUMBER = re.compile(r"[-+−]?\d+(?:\.\d+)?")


def results_block(result: Result) -> str:
    """The generated table: design to build, energies at their boundaries, thermal state, hydraulic baseline."""
    build = result.optimal.lengths if result.buildable is None else result.buildable.lengths
    rows = []
    for name in CHAIN_NAMES:
        before, after = getattr(result.initial.lengths, name), getattr(build, name)
        rows.append(
            f"| {name} L / Lc0 / Lc, built → to build | {before.L:.3f} / {before.Lc0:.3f} / {before.Lc:.3f} m "
            f"→ {after.L:.3f} / {after.Lc0:.3f} / {after.Lc:.3f} m |"
        )
    i, o = result.initial, result.optimal
    rows.append(
        f"| net electrical energy (drive inputs, DC side with the inverter loss) | {i.net_electrical_energy_J:.1f} → "
        f"{o.net_electrical_energy_J:.1f} J "
        f"({-result.improvement.net_energy_saved_percent:.2f} %) |"
    )
    if result.energy is not None:
        e = result.energy
        rows.append(
            f"| battery energy per duty period, cycle and rest (at the battery) | {e.initial.battery_energy_J:.1f} → "
            f"{e.optimal.battery_energy_J:.1f} J ({-e.battery_energy_saved_percent:.2f} %) |"
        )
        for motor, t in (e.optimal.thermal or {}).items():
            rows.append(
                f"| {motor} motor at the optimum, {e.duty} | RMS torque {t.rms_torque_Nm:.2f} of "
                f"{t.continuous_torque_Nm:.1f} N m, winding {t.peak_winding_temperature_C:.1f} of "
                f"{t.max_winding_temperature_C:.0f} °C |"
            )
    if result.hydraulic_baseline is not None:
        h = result.hydraulic_baseline.optimal
        rows.append(
            f"| hydraulic cylinders, same motion, at the pump motor input (load sensing / constant pressure) | "
            f"{h.load_sensing.input_energy_J / 1e3:.2f} / {h.constant_pressure.input_energy_J / 1e3:.2f} kJ |"
        )
    d = result.improvement.decomposition
    if d.from_lengths_J is not None:
        rows.append(f"| saving from the lengths alone | {d.from_lengths_J:.1f} J |")
    rows.append(
        f"| re-check ({result.recheck.id_path}, {result.recheck.grid_points} points): TCP error | "
        f"{1e3 * result.recheck.tracking_error.position_m:.2f} mm |"
    )
    return "\n".join(["| quantity | value |", "|---|---|", *rows])


def current_block(page: str) -> str:
    """The text between the markers."""
    start, end = page.find(START), page.find(END)
    if start < 0 or end < start:
        raise ValueError(f"the page must contain {START} followed by {END}")
    return page[start + len(START) : end].strip()


def _close(old: str, new: str) -> bool:
    a, b = float(old.replace("−", "-")), float(new.replace("−", "-"))
    digits = len(new.split(".")[1]) if "." in new else 0
    return abs(a - b) <= max(RELATIVE_TOLERANCE * abs(b), 10.0**-digits * 1.000001)


def differences(written: str, fresh: str) -> list[str]:
    """Where the page's block differs from a fresh one beyond the tolerance (one message per line)."""
    old_lines, new_lines = written.strip().splitlines(), fresh.strip().splitlines()
    if len(old_lines) != len(new_lines):
        return [f"the page's table has {len(old_lines)} lines, a fresh one {len(new_lines)}"]
    out = []
    for row, (old, new) in enumerate(zip(old_lines, new_lines, strict=True), start=1):
        a, b = NUMBER.findall(old), NUMBER.findall(new)
        if NUMBER.sub("#", old) != NUMBER.sub("#", new) or len(a) != len(b):
            out.append(f"line {row}: page {old!r} != fresh {new!r}")
        elif not all(_close(x, y) for x, y in zip(a, b, strict=True)):
            out.append(f"line {row}: page {old!r} vs fresh {new!r} (beyond {RELATIVE_TOLERANCE:g} relative)")
    return out


def main(argv: list[str] | None = None) -> int:
    """Update or check a results page from a run folder."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("--page", type=Path, default=Path("docs/results/default-study.md"))
    parser.add_argument("--check", action="store_true", help="exit 1 when the page is stale; write nothing")
    args = parser.parse_args(argv)
    page = args.page.read_text()
    fresh = results_block(read_result(args.run_dir))
    if args.check:
        stale = differences(current_block(page), fresh)
        for line in stale:
            print(f"results_page: {args.page} is stale: {line}", file=sys.stderr)
        return 1 if stale else 0
    current_block(page)
    start, end = page.find(START), page.find(END)
    write_atomic(args.page, page[: start + len(START)] + "\n" + fresh + "\n" + page[end:])
    print(f"updated {args.page} from {args.run_dir}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

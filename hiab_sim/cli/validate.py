"""``hiab-sim validate``: cross-validate the MuJoCo and analytic inverse dynamics.

Runs the cases of ``validate/cases.yaml`` (see :mod:`hiab_sim.validation`), writes
``report.json``, ``table.md`` and one ``forces_<case>.png`` per case into ``--out``, prints the
table, and exits 1 when any error exceeds its tolerance (2 on bad input).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from hiab_sim.errors import InvalidInputError

#: ``--samples`` presets: samples per case.
SAMPLE_PRESETS = {"small": 24}


def _samples(text: str) -> int | None:
    if text == "full":
        return None
    if text in SAMPLE_PRESETS:
        return SAMPLE_PRESETS[text]
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, 'small' or 'full', got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "validate",
        help="Cross-validate MuJoCo and analytic inverse dynamics (forces, velocities, power balance).",
        description=(
            "Run both inverse-dynamics paths on random states, a smooth trajectory, >= 20 random link-length "
            "sets and static poses, each with and without a TCP payload; report the errors and each path's "
            "energy balance. Exit status 1 when any error exceeds its tolerance."
        ),
    )
    parser.add_argument("--crane", default="xs031", help="crane preset or YAML file (default: xs031)")
    parser.add_argument(
        "--cases", type=Path, default=None, metavar="FILE.yaml", help="case file (default: validate/cases.yaml)"
    )
    parser.add_argument(
        "--samples",
        type=_samples,
        default=None,
        metavar="N|small|full",
        help="samples per case (default 'full': as in the case file; 'small' = 24)",
    )
    parser.add_argument(
        "--out", type=Path, default=Path("runs/validate"), help="output folder (default: runs/validate)"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run every case, write the report files and return 0 (all within tolerance) or 1."""
    from hiab_sim.crane.loader import load_crane
    from hiab_sim.validation import DEFAULT_CASES, load_cases, mujoco_path, run_case, with_samples
    from hiab_sim.validation_report import write_report

    crane = load_crane(args.crane)
    tolerances, specs = load_cases(args.cases or DEFAULT_CASES)
    if args.samples is not None:
        specs = with_samples(specs, args.samples)
    if args.out.exists() and not args.out.is_dir():
        raise InvalidInputError("--out", str(args.out), "must be a folder")
    mujoco = mujoco_path(crane)
    results = []
    for spec in specs:
        start = time.perf_counter()
        result = run_case(crane, spec, mujoco, tolerances)
        results.append(result)
        status = "ok" if result.passed else "FAILED"
        print(
            f"{spec.name:<24} {result.samples:>6} samples  force {max(result.force_rel_error):.1e}  "
            f"velocity {max(result.velocity_abs_error):.1e} m/s  balance {result.balance_analytic:.1e} / "
            f"{result.balance_mujoco:.1e}  {status}  ({time.perf_counter() - start:.1f} s)"
        )
    written = write_report(args.out, crane, results, tolerances)
    print()
    print((args.out / "table.md").read_text())
    print(f"wrote {len(written)} files to {args.out}")
    failed = [r.name for r in results if not r.passed]
    if failed:
        print(f"validation FAILED: {', '.join(failed)}")
        return 1
    print("validation passed")
    return 0

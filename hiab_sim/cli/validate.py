"""``hiab-sim validate``: cross-validate the MuJoCo and analytic inverse dynamics.

Runs the cases of ``validate/cases.yaml`` (see :mod:`hiab_sim.validation`), writes
``report.json``, ``table.md`` and one ``forces_<case>.png`` per case into ``--out``, prints the
table, and exits 1 when any error exceeds its tolerance (2 on bad input).

``--machine NAME|FILE`` validates a machine file's two paths instead (Newton-Euler vs MuJoCo,
:mod:`hiab_sim.machine_validation`): random states within the joint ranges without and with a TCP
force (``--tcp-force FX,FY`` [N]), written as ``report.json`` and ``table.md``.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol

from hiab_sim.cli.options import DEFAULT_CRANE, add_crane_option, add_machine_option
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
            "Run both inverse-dynamics paths of the crane file on random states, a smooth trajectory, >= 20 random "
            "link-length sets and static poses, each with and without a TCP payload; report the errors and each "
            "path's energy balance. With --machine: a machine file's Newton-Euler and MuJoCo paths on random "
            "states within its joint ranges, without and with a TCP force (--tcp-force). Exit status 1 when any "
            "error exceeds its tolerance."
        ),
    )
    add_crane_option(parser, f"crane preset or YAML file (default: {DEFAULT_CRANE})")
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
    add_machine_option(
        parser,
        "validate a machine file's paths (Newton-Euler vs MuJoCo) instead of the crane's (shipped: xs031, exact)",
    )
    parser.add_argument(
        "--tcp-force",
        metavar="FX,FY",
        help="with --machine: TCP force [N] in the world plane, y up (default: 0,-2452, a 250 kg payload)",
    )
    parser.add_argument(
        "--out", type=Path, default=Path("runs/validate"), help="output folder (default: runs/validate)"
    )
    parser.set_defaults(run=run, crane=None)  # --crane unless given: None (DEFAULT_CRANE on the crane path)


#: ``--machine``'s samples per case with ``--samples full`` (the default).
MACHINE_SAMPLES = 200


def _tcp_force(text: str | None) -> tuple[float, float]:
    from hiab_sim.machine_validation import DEFAULT_TCP_FORCE

    if text is None:
        return DEFAULT_TCP_FORCE
    try:
        fx, fy = (float(v) for v in text.split(","))
    except ValueError:
        raise InvalidInputError("--tcp-force", text, "must be two numbers FX,FY", "N") from None
    if not (math.isfinite(fx) and math.isfinite(fy)):
        raise InvalidInputError("--tcp-force", text, "must be finite", "N")
    return fx, fy


def run_machine(args: argparse.Namespace) -> int:
    """The machine's two cases: print the table, write report.json and table.md, return 0 or 1."""
    import json
    from dataclasses import asdict

    from hiab_sim.atomic_io import write_atomic
    from hiab_sim.machine.loader import load_machine
    from hiab_sim.machine_validation import machine_cases, machine_table
    from hiab_sim.validation import DEFAULT_CASES, load_cases

    machine = load_machine(args.machine)
    tolerances, _ = load_cases(args.cases or DEFAULT_CASES)  # one source of the tolerances
    force = _tcp_force(args.tcp_force)
    if args.out.exists() and not args.out.is_dir():
        raise InvalidInputError("--out", str(args.out), "must be a folder")
    results = machine_cases(machine, args.samples or MACHINE_SAMPLES, force, tolerances)
    table = machine_table(machine, results, tolerances)
    args.out.mkdir(parents=True, exist_ok=True)
    report = {
        "machine": machine.name,
        "tolerances": asdict(tolerances),
        "passed": all(r.passed for r in results),
        "cases": [asdict(r) for r in results],
    }
    write_atomic(args.out / "report.json", json.dumps(report, indent=2))
    write_atomic(args.out / "table.md", table)
    print(table)
    print(f"wrote 2 files to {args.out}")
    return verdict(results)


class CaseOutcome(Protocol):
    """What the verdict reads of a case's result (crane or machine file)."""

    @property
    def name(self) -> str:
        """The case's name."""
        ...

    @property
    def passed(self) -> bool:
        """Whether every error of the case is within its tolerance."""
        ...


def verdict(results: Sequence[CaseOutcome]) -> int:
    """Print the verdict over the cases and return the exit status: 0 all within tolerance, else 1."""
    failed = [r.name for r in results if not r.passed]
    if failed:
        print(f"validation FAILED: {', '.join(failed)}")
        return 1
    print("validation passed")
    return 0


def run(args: argparse.Namespace) -> int:
    """Run every case, write the report files and return 0 (all within tolerance) or 1."""
    if args.machine is not None:
        if args.crane is not None:
            raise InvalidInputError("--crane", args.crane, "cannot be combined with --machine")
        return run_machine(args)
    if args.tcp_force is not None:
        raise InvalidInputError("--tcp-force", args.tcp_force, "needs --machine (the crane's cases set their payload)")
    from hiab_sim.crane.loader import load_crane
    from hiab_sim.validation import DEFAULT_CASES, load_cases, mujoco_path, run_case, with_samples
    from hiab_sim.validation_report import write_report

    crane = load_crane(args.crane or DEFAULT_CRANE)
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
    return verdict(results)

"""``hiab-sim report``: the design report of a result folder, one self-contained HTML file (optionally PDF)."""

from __future__ import annotations

import argparse


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "report",
        help="Write the design report of a result folder: one self-contained HTML file to hand on.",
        description=(
            "One HTML file with every figure embedded and no network reference: the question and the machine, the "
            "design to build with its structure drawing and pivot moves, the energies and their boundaries, the "
            "constraints and margins at the optimum, the thermal state, the sensitivities, the hydraulic "
            "comparison, the closed-loop validation (when simulation.json exists), the duty mix and its "
            "cross-evaluation (when present) and the provenance."
        ),
        epilog="exit status: 0 done; 2 bad input (no result folder, an unreadable result, no browser for --pdf)",
    )
    parser.add_argument("run_dir", metavar="RUN_DIR", help="result folder written by hiab-sim optimize")
    parser.add_argument("-o", "--out", metavar="FILE.html", help="output file (default: RUN_DIR/report.html)")
    parser.add_argument("--pdf", action="store_true", help="also print it to FILE.pdf with headless Chromium")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Write the report; return the exit status."""
    from hiab_sim.design_report import write_report

    for path in write_report(args.run_dir, args.out, pdf=args.pdf):
        print(f"wrote {path}")
    return 0

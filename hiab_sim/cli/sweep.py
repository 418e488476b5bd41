"""``hiab-sim sweep``: many optimisations over a grid or a Latin-hypercube sample, on local processes or Dask."""

from __future__ import annotations

import argparse
from pathlib import Path

from hiab_sim.cli.options import add_out_option


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "sweep",
        help="Optimise a study at every point of a parameter grid or sample; one table of results.",
        description=(
            "Run a full optimisation at every point of SWEEP.yaml (a base study and a grid or a Latin-hypercube "
            "sample over dotted study paths such as payload, emla.lift.gear_ratio or, in a crane file's study, "
            "bounds.lift.up[0]; a machine file's study has no bounds.<chain>: its decision variables' bounds are the "
            "machine file's, moved by sweeping machine over copies of that file). Every point's "
            "study is validated before any work starts. Results: DIR/sweep.parquet (one row per point, written "
            "atomically as points finish), DIR/points/<key>/result.json, summary figures and DIR/summary.md; DIR "
            "holding another command's output (e.g. an optimisation's result.json) is refused."
        ),
    )
    parser.add_argument("sweep", metavar="SWEEP.yaml", help="sweep file")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N", help="local worker processes (default 1)")
    where.add_argument("--dask", metavar="ADDRESS", help="Dask scheduler, e.g. tcp://127.0.0.1:8786")
    add_out_option(parser, "runs/sweeps/<sweep name>")
    parser.add_argument("--resume", action="store_true", help="skip the points already in DIR/sweep.parquet")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run the sweep, print its answer first (also ``summary.md``), then the details; return the exit status."""
    from hiab_sim.cli.answer_output import ANSWER_FILE, publish_answer
    from hiab_sim.results.read import read_result
    from hiab_sim.sweep.answers import sweep_answer
    from hiab_sim.sweep.executors import make_executor
    from hiab_sim.sweep.figures import summary_figures
    from hiab_sim.sweep.out_folder import check_out_folder
    from hiab_sim.sweep.runner import run_sweep
    from hiab_sim.sweep.spec import load_sweep
    from hiab_sim.sweep.table import read_table

    sweep = load_sweep(args.sweep)
    out = Path(args.out) if args.out else Path("runs") / "sweeps" / sweep.name
    check_out_folder(out, "sweep", "sweep")
    where = f"Dask at {args.dask}" if args.dask else f"{args.workers or 1} local process(es)"
    with make_executor(args.workers, args.dask) as executor:
        outcome = run_sweep(sweep, out, executor, resume=args.resume, progress=not args.quiet)
    frame, _ = read_table(outcome.table)
    ok = frame["status"] == "ok"
    per = "cycle"
    if ok.any():  # every point runs the same study's duty model: a finished point's result says which period
        energy = read_result(out / "points" / str(frame.loc[ok, "key"].iloc[0])).energy
        if energy is not None and energy.optimal.duty is not None:
            per = "duty period (the cycle and the rest's hold)"
    figures = summary_figures(frame, list(sweep.axes), out, sweep.name, per.split(" (")[0])
    details = [
        f"sweep {sweep.name}: {len(sweep.points)} points of {sweep.study_file.name} on {where}",
        f"ran {len(outcome.ran)} point(s), skipped {len(outcome.skipped)} finished, {len(outcome.failed)} failed now; "
        f"table: {int(ok.sum())} ok of {len(frame)}",
    ]
    if ok.any():
        saving = frame.loc[ok, "net_energy_saved_percent"]
        details.append(f"net energy saved: {saving.min():.2f} .. {saving.max():.2f} % over the ok points")
    details += [f"  failed {row['key']}: {row['message']}" for _, row in frame[~ok].iterrows()]
    files = [outcome.table.name, "points/<key>/result.json", *(p.name for p in figures), ANSWER_FILE]
    publish_answer(sweep_answer(frame, list(sweep.axes), sweep.name, out, files, per), out, details)
    return 0

"""``hiab-sim pareto``: the front of the study's objective against a second criterion (epsilon-constraint method)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from hiab_sim.cli.options import add_out_option


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "pareto",
        help="Pareto front of the energy objective against peak actuator force or rms motor torque.",
        description=(
            "Optimise the study, find the least criterion its constraints allow, and minimise the study's "
            "objective (any registered one, in its unit; for a duty mix the weighted sum over its tasks, every "
            "task's constraints held and the criterion the worst over the tasks) with criterion <= epsilon for "
            "epsilon from the optimum's criterion down to that least value, each a full optimisation by the study's "
            "own solver (SLSQP or IPOPT, solver.method). Crane files and machine files alike. Writes pareto.csv, "
            "pareto.json, pareto.png and summary.md into a folder of its own (a folder holding another command's "
            "output, e.g. an optimisation's result.json, is refused: its summary.md would be overwritten)."
        ),
    )
    parser.add_argument(
        "study", nargs="?", metavar="STUDY.yaml", help="study file (default: optimize/xs031_spiral.yaml)"
    )
    parser.add_argument("--against", required=True, choices=("peak_force", "rms_torque"), help="second criterion")
    parser.add_argument("--points", type=int, default=10, metavar="K", help="front points (default 10)")
    add_out_option(parser, "runs/<study name>/pareto_<criterion>")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Compute the front, write the table and figure, print the answer first (``summary.md``); return the status."""
    import pandas as pd

    from hiab_sim.atomic_io import write_atomic
    from hiab_sim.cli.answer_output import ANSWER_FILE, publish_answer
    from hiab_sim.study.nlp.problem import make_problem
    from hiab_sim.study.solvers.slsqp import check_start, solve
    from hiab_sim.study.spec.study_file import DEFAULT_STUDY, load_study
    from hiab_sim.sweep.answers import front_answer
    from hiab_sim.sweep.out_folder import check_out_folder
    from hiab_sim.sweep.pareto import CRITERIA, pareto_front
    from hiab_sim.sweep.pareto_figure import front_figure_png
    from hiab_sim.terminal import StatusLine

    if args.points < 2:
        from hiab_sim.errors import InvalidInputError

        raise InvalidInputError("--points", args.points, "must be >= 2")
    study = load_study(args.study or DEFAULT_STUDY)
    out = Path(args.out) if args.out else Path("runs") / study.name / f"pareto_{args.against}"
    check_out_folder(out, "pareto", f"pareto_{args.against}")
    study_problem = make_problem(study)
    check_start(study_problem, study_problem.initial_point(study.initial_lengths))
    with StatusLine(f"optimising {study.name} and {args.points - 1} limits on the {args.against} ..."):
        optimum = solve(study_problem, study.initial_lengths, progress=None)
        traced = pareto_front(study_problem, optimum.z, args.against, args.points)
    front = traced.points
    frame = pd.DataFrame([p.as_row() for p in front])
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / "pareto.csv", frame.to_csv(index=False))
    unit = CRITERIA[args.against]
    summary = {
        "study": study.path,
        "criterion": args.against,
        "unit": unit,
        "criterion_note": "the worst over the tasks" if study_problem.n_tasks > 1 else "over the cycle",
        "objective_name": study_problem.objective.name,
        "objective_unit": study_problem.objective.unit,
        "tasks": [{"name": t.name, "weight": float(t.weight)} for t in study.tasks],
        "design_variables": list(study.model.design_names),
        "points": frame.to_dict("records"),
        # the least criterion the study's constraints allow, at the design minimising it alone (not on the front)
        "least_criterion": traced.least.as_row(),
    }
    write_atomic(out / "pareto.json", json.dumps(summary, indent=2) + "\n")
    write_atomic(
        out / "pareto.png",
        front_figure_png(front, args.against, study.name, study_problem.objective.name, traced.least),
    )
    details = []
    for p in front:
        status = "ok" if p.accepted else f"not converged: {p.message}"
        details.append(
            f"epsilon {p.epsilon:12.6g} {unit}  criterion {p.criterion:12.6g}  objective {p.objective:.6f}  "
            f"({p.iterations} iterations, {status})"
        )
    files = ["pareto.csv", "pareto.json", "pareto.png", ANSWER_FILE]
    answer = front_answer(front, args.against, study_problem.objective.name, study.name, out, files, traced.least)
    publish_answer(answer, out, details)
    return 0

"""``hiab-sim energy-map``: the objective, net energy and binding constraint over a grid of two link lengths."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "energy-map",
        help="Map the objective and net energy over two link lengths (the rest and the trajectory fixed).",
        description=(
            "Evaluate the study's objective (by default the seed paper's squared-power cost costf2 in W^2 s), "
            "the net electrical energy and the constraints that depend on the link lengths only on an "
            "N x N grid of two link lengths over their bounds, the other four and the joint trajectory fixed at "
            "the optimum of --result (or the study's start), on the analytic ID path, vectorised over designs. "
            "Infeasible cells are coloured by their binding constraint."
        ),
    )
    parser.add_argument(
        "study",
        nargs="?",
        metavar="STUDY.yaml",
        help="study file (default: the --result run's study, else optimize/xs031_spiral.yaml)",
    )
    parser.add_argument(
        "--vars",
        default=None,
        help="two decision variables of the study, e.g. lift.L,tilt.L on the XS 031 (default: the first two of "
        "its first chain, the XS 031's lift.L,lift.Lc0: with working_range crane a chain's L and Lc0 together "
        "keep its stroke on the joint range, so their map has a feasible region)",
    )
    parser.add_argument("--grid", type=int, default=50, metavar="N", help="grid points per axis (default 50)")
    parser.add_argument("--result", metavar="DIR", help="result folder of hiab-sim optimize: map around its optimum")
    parser.add_argument("--out", metavar="DIR", help="output folder (default: runs/<study name>/energy_map)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Compute and write the map, print its answer first and save it as ``summary.md``; return the exit status."""
    from hiab_sim.cli.answer_output import ANSWER_FILE, publish_answer
    from hiab_sim.study.nlp.task_problem import TaskProblem
    from hiab_sim.study.report.summary import limit_in_words
    from hiab_sim.study.spec.study_file import DEFAULT_STUDY, load_study
    from hiab_sim.sweep.answers import map_answer
    from hiab_sim.sweep.energy_map import energy_map, optimum_design, parse_variables, result_study, start_design
    from hiab_sim.sweep.map_output import TRAJECTORY_NOTE, summary, write_map
    from hiab_sim.terminal import StatusLine

    study = load_study(args.study or (result_study(args.result) if args.result else DEFAULT_STUDY))
    problem = TaskProblem(study, id_path="analytic")
    variables = parse_variables(args.vars or ",".join(problem.model.design_names[:2]))
    base = optimum_design(args.result) if args.result else start_design(problem)
    with StatusLine(f"evaluating {args.grid} x {args.grid} mountings ..."):
        m = energy_map(problem, base, variables, args.grid)
    out = Path(args.out) if args.out else Path("runs") / study.name / "energy_map"
    paths = write_map(m, out)
    s = summary(m)
    per = "cycle" if problem.duty_options is None else "duty period (the cycle and the rest's hold)"
    answer = map_answer(m, s, study.name, per, out, [*(p.name for p in paths), ANSWER_FILE])
    at = s["at_base"]
    details = [
        f"energy map {m.variables[0]} x {m.variables[1]}, {args.grid} x {args.grid} cells; base: {m.base.source}",
        f"fixed: {', '.join(f'{k} = {v:.4f} m' for k, v in s['fixed'].items())}; {TRAJECTORY_NOTE}",
        f"at the base: objective {at['objective']:.6f}, net energy {at['net_electrical_energy_J'] / 1e3:.3f} kJ, "
        f"battery energy {at['battery_energy_J'] / 1e3:.3f} kJ, binding: {limit_in_words(at['binding_constraint'])} "
        f"(margin {at['smallest_margin']:.2e})",
    ]
    best = s["best_feasible_cell"]
    if best is not None:
        xi = best["xi_m"]
        i0, i1 = variables
        details.append(
            f"{s['feasible_cells']} of {s['cells']} cells feasible; best: {m.variables[0]} = {xi[i0]:.4f} m, "
            f"{m.variables[1]} = {xi[i1]:.4f} m, objective {best['objective']:.6f}, "
            f"net energy {best['net_electrical_energy_J'] / 1e3:.3f} kJ, battery energy "
            f"{best['battery_energy_J'] / 1e3:.3f} kJ"
        )
    publish_answer(answer, out, details)
    return 0

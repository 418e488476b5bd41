"""``hiab-sim energy-map``: the objective, net energy and binding constraint over a grid of two link lengths."""

from __future__ import annotations

import argparse
from pathlib import Path

from hiab_sim.cli.options import add_out_option


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "energy-map",
        help="Map the objective and net energy over two decision variables (the rest and the trajectory fixed).",
        description=(
            "Evaluate the study's objective (any registered one, in its unit and relative to the study's start; "
            "for a duty mix the weighted sum over its tasks), the squared-power cost costf2 [W^2 s], the net and "
            "battery energies and the constraints that depend on the decision variables on an N x N grid of two "
            "of the machine's decision variables over their bounds, the others and every task's joint trajectory "
            "fixed at the optimum of --result (or the study's start), on the analytic ID path. Crane files and "
            "machine files alike. Infeasible cells are coloured by their binding constraint. Writes "
            "energy_map.json, energy_map.npz, energy_map.png and summary.md into a folder of its own (a folder "
            "holding another command's output, e.g. the --result folder, is refused: its summary.md would be "
            "overwritten)."
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
        help="two of the machine's decision variables, e.g. lift.L,tilt.L or boom.L,arm.L (default: its first "
        "two, lift.L,lift.Lc0 on the XS 031: a chain's L and Lc0 together keep its stroke on the joint range, "
        "so their map has a feasible region)",
    )
    parser.add_argument("--grid", type=int, default=50, metavar="N", help="grid points per axis (default 50)")
    parser.add_argument("--result", metavar="DIR", help="result folder of hiab-sim optimize: map around its optimum")
    add_out_option(parser, "runs/<study name>/energy_map")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Compute and write the map, print its answer first and save it as ``summary.md``; return the exit status."""
    from hiab_sim.cli.answer_output import ANSWER_FILE, publish_answer
    from hiab_sim.errors import InvalidInputError
    from hiab_sim.study.nlp.problem import StudyProblem
    from hiab_sim.study.report.summary import limit_in_words
    from hiab_sim.study.spec.study_file import DEFAULT_STUDY, load_study
    from hiab_sim.sweep.answers import map_answer
    from hiab_sim.sweep.energy_map import energy_map, optimum_design, parse_variables, result_study, start_design
    from hiab_sim.sweep.map_output import TRAJECTORY_NOTE, energy_words, objective_words, summary, write_map
    from hiab_sim.sweep.out_folder import check_out_folder
    from hiab_sim.terminal import StatusLine

    if args.grid < 2:
        raise InvalidInputError("--grid", args.grid, "must be >= 2")
    study = load_study(args.study or (result_study(args.result) if args.result else DEFAULT_STUDY))
    variables = parse_variables(args.vars, tuple(study.model.design_names))
    out = Path(args.out) if args.out else Path("runs") / study.name / "energy_map"
    check_out_folder(out, "energy-map", "energy_map")
    problem = StudyProblem(study, id_path="analytic")
    base = optimum_design(args.result, problem) if args.result else start_design(problem)
    with StatusLine(f"evaluating {args.grid} x {args.grid} mountings on {problem.n_tasks} task(s) ..."):
        m = energy_map(problem, base, variables, args.grid)
    duty = problem.problems[0].duty_options is not None
    per = "cycle" if not duty else "duty period (the cycle and the rest's hold)"
    paths = write_map(m, out, per.split(" (")[0])
    s = summary(m)
    if problem.n_tasks > 1:
        per = f"{per} of each task, {energy_words(m)}"
    answer = map_answer(m, s, study.name, per, out, [*(p.name for p in paths), ANSWER_FILE])
    at = s["at_base"]
    details = [
        f"energy map {m.variables[0]} x {m.variables[1]}, {args.grid} x {args.grid} cells; base: {m.base.source}",
        f"objective: {objective_words(m)}",
        f"fixed: {', '.join(f'{k} = {v:.4f} m' for k, v in s['fixed'].items())}; {TRAJECTORY_NOTE}",
        f"at the base: objective {at['objective']:.6f} of the start's ({at['objective_value']:.6g} "
        f"{m.objective_unit}), net energy {at['net_electrical_energy_J'] / 1e3:.3f} kJ, "
        f"battery energy {at['battery_energy_J'] / 1e3:.3f} kJ, binding: {limit_in_words(at['binding_constraint'])} "
        f"(margin {at['smallest_margin']:.2e})",
    ]
    best = s["best_feasible_cell"]
    if best is not None:
        xi = best["xi_m"]
        i0, i1 = variables
        details.append(
            f"{s['feasible_cells']} of {s['cells']} cells feasible; best: {m.variables[0]} = {xi[i0]:.4f} m, "
            f"{m.variables[1]} = {xi[i1]:.4f} m, objective {best['objective']:.6f} "
            f"({best['objective_value']:.6g} {m.objective_unit}), "
            f"net energy {best['net_electrical_energy_J'] / 1e3:.3f} kJ, battery energy "
            f"{best['battery_energy_J'] / 1e3:.3f} kJ"
        )
    publish_answer(answer, out, details)
    return 0

"""``hiab-sim optimize``: energy-optimal actuator mounting (every chain's decision variables) of a study.

Runs a study (default ``optimize/xs031_spiral.yaml``) with SQP, prints one line per iteration to
stderr with ``--verbose``, and writes ``result.json``, ``trajectory.npz``, the figures, the playback
video and ``summary.md`` into the output folder; the console ends with that summary
(:mod:`hiab_sim.study.report.summary`). Bad input exits 2 before anything is written; a solver failure exits 1 and
keeps the partial history (``checkpoint_<k>.json``) for ``--resume``. A start that violates
constraints goes through the feasibility phase (:mod:`hiab_sim.study.solvers.feasibility`); when no point
within the bounds is feasible the run exits 3 and names the binding limit. With ``--verbose`` stdout
also prints the full report before the summary: the design rounded to the study's ``build.tolerance``
with its re-checks and export command, and the largest multipliers of the optimality conditions
(``result.json`` -> ``buildable``, ``feasibility``, ``sensitivity``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from hiab_sim.atomic_io import write_atomic
from hiab_sim.cli.options import add_out_option
from hiab_sim.errors import BackendUnavailableError
from hiab_sim.results.design_values import design_words
from hiab_sim.study.report.summary import SUMMARY_FILE, summary_text

if TYPE_CHECKING:
    from hiab_sim.results.schema import Decomposition, Result


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "optimize",
        help="Optimise the actuators' mounting (every chain's decision variables) for least EMLA energy.",
        description=(
            "Minimise the seed paper's squared-power cost (costf2 = 1/2 Dt sum over samples of the squared total "
            "EMLA electrical power, in W^2 s; a smooth stand-in for energy, not an energy) over "
            "every chain's decision variables (the crane file's link lengths, a machine file's declared ones) and "
            "the B-spline joint trajectory, subject to inverse dynamics, tracking of the study's tasks, the EMLA "
            "envelope, stroke, triangle and joint limits (SLSQP or IPOPT). A study may "
            "instead minimise the battery's energy (objective: battery_energy), add the motors' thermal limits "
            "(duty:) and enumerate a transmission catalogue (transmission:); every result reports the battery "
            "energy, costf2, thermal margins and the hydraulic baseline."
        ),
        epilog=(
            "exit status: 0 done; 1 the solver failed (partial history kept for --resume); 2 bad input "
            "(nothing written); 3 no feasible point within the bounds (the binding limit is named)"
        ),
    )
    parser.add_argument(
        "study", nargs="?", metavar="STUDY.yaml", help="study file or shipped study name (default: xs031_spiral)"
    )
    add_out_option(parser, "runs/<study name>")
    parser.add_argument("--resume", action="store_true", help="continue from the output folder's last checkpoint")
    parser.add_argument(
        "--starts", type=int, metavar="K", help="number of feasible starts (default: 1; with --resume the run's own)"
    )
    parser.add_argument("--force", action="store_true", help="write into a folder that belongs to another study")
    parser.add_argument("--id", choices=("mujoco", "analytic"), help="inverse-dynamics path (default: the study's)")
    parser.add_argument("--no-video", action="store_true", help="do not render the playback video")
    parser.add_argument("--no-figures", action="store_true", help="do not draw the figures (quick runs)")
    parser.add_argument("--no-report", action="store_true", help="do not write the design report (report.html)")
    parser.add_argument(
        "--verbose",
        action="store_true",
        help="also print each iteration and the full report (solver, re-check, decomposition, sensitivities)",
    )
    parser.add_argument("--quiet", action="store_true", help="only the summary (the default; kept for scripts)")
    parser.set_defaults(run=run)


def decomposition_line(d: Decomposition) -> str:
    """One line: the net-energy saving from the lengths alone and from the trajectory alone."""

    def part(saved: float | None, percent: float | None, key: str) -> str:
        design = d.designs[key]
        if saved is None or percent is None or not design.evaluable or design.max_violation is None:
            return "not evaluable"
        return f"{saved:.1f} J ({percent:.2f} %, max violation {design.max_violation:.1e})"

    interaction = d.interaction_J
    return (
        "net energy saved from the lengths alone (initial trajectory): "
        f"{part(d.from_lengths_J, d.from_lengths_percent, 'optimal_lengths_initial_trajectory')}, "
        "from the trajectory (initial lengths): "
        f"{part(d.from_trajectory_J, d.from_trajectory_percent, 'initial_lengths_optimal_trajectory')}, "
        f"interaction {'n/a' if interaction is None else f'{interaction:.1f} J'}"
    )


def summary_lines(r: Result) -> list[str]:
    """The run's summary as printed to stdout: designs, solver, decomposition, re-check, multi-start."""
    lines = []
    for name, entry in (("initial", r.initial), ("optimal", r.optimal)):
        lines.append(
            f"{name:8s} {design_words(entry.lengths)}  "
            f"net motor energy {entry.net_electrical_energy_J / 1e3:.3f} kJ  "
            f"drawn {entry.drawn_energy_summed_drives_J / 1e3:.3f} kJ (motor side; battery below)"
        )
    sol, rc = r.solver, r.recheck
    lines.append(
        f"{sol.method.split()[0]}: {sol.message} ({sol.iterations} iterations, {sol.wall_time_s:.1f} s, "
        f"max violation {sol.max_violation_scaled:.1e}); cost ratio {r.improvement.cost_ratio:.4f}, "
        f"net energy -{r.improvement.net_energy_saved_percent:.2f} %"
    )
    lines.append(decomposition_line(r.improvement.decomposition))
    lines.append(
        f"re-check ({rc.id_path}, {rc.grid_points} points): max violation {rc.max_violation_scaled:.1e}, "
        f"TCP tracking error {rc.tracking_error.position_m * 1e3:.3f} mm"
    )
    from hiab_sim.study.report.analysis_sections import extra_lines

    lines += extra_lines(r)
    ms = r.multistart
    if len(ms.starts) > 1:
        converged = ms.converged_starts
        if ms.same_optimum and not ms.failed_starts:
            lines.append(f"multi-start: all {converged} starts reach the same optimum within {ms.tolerance_m} m")
        elif ms.same_optimum:
            lines.append(
                f"multi-start: all {converged} converged starts reach the same optimum within {ms.tolerance_m} m"
            )
        else:
            count = len(ms.distinct_optima)
            lines.append(f"multi-start: {count} distinct local optima among {converged} converged starts:")
            for d in ms.distinct_optima:
                xi = " ".join(f"{v:.4f}" for v in d.xi)
                energy = "n/a" if d.net_electrical_energy_J is None else f"{d.net_electrical_energy_J / 1e3:.3f}"
                value = (
                    "" if d.objective_value is None else f"  {ms.objective} {d.objective_value:.9g} {ms.objective_unit}"
                )
                lines.append(f"  Xi [{xi}] m  net energy {energy} kJ{value}  starts {list(d.starts)}")
        for f in ms.failed_starts:
            lines.append(f"  start {f.start} failed (not an optimum): {f.message}")
    return lines


def run(args: argparse.Namespace) -> int:
    """Run the study and print a summary; return the exit status."""
    from hiab_sim.study.run import run_study
    from hiab_sim.study.run_safety import resolve_starts
    from hiab_sim.study.spec.study_file import DEFAULT_STUDY, load_study

    study = load_study(args.study or DEFAULT_STUDY)
    out = Path(args.out) if args.out else Path("runs") / study.name
    output = run_study(
        study,
        out,
        starts=resolve_starts(out, args.starts, args.resume),
        resume=args.resume,
        force=args.force,
        id_path=args.id,
        progress=sys.stderr if args.verbose else None,
        figures=not args.no_figures,
    )
    if output.removed:
        names = ", ".join(sorted(p.name for p in output.removed))
        print(f"removed all {len(output.removed)} output file(s) of the earlier run in {output.folder}: {names}")
    if args.verbose:
        from hiab_sim.study.analysis.codesign import codesign_lines
        from hiab_sim.study.report.energy_section import energy_lines

        codesign = [] if output.result.codesign is None else codesign_lines(output.result.codesign)
        for line in [*summary_lines(output.result), *energy_lines(output.result), *codesign]:
            print(line)
    files = ["result.json", "trajectory.npz", SUMMARY_FILE]
    if (output.folder / output.result.crane).is_file():  # the crane or machine file copied next to the result
        files.append(output.result.crane)
    if output.figures:
        files.append(f"{len(output.figures)} figures (*.png)")
    if not args.no_video:
        try:
            from hiab_sim.render import render_result

            video = render_result(output.folder, output.folder / "playback.mp4")
            files.append(video.name)
        except BackendUnavailableError as error:
            print(f"hiab-sim optimize: no video: {error}", file=sys.stderr)
    if not args.no_report:
        from hiab_sim.design_report import write_report

        files.extend(path.name for path in write_report(output.folder))
    text = summary_text(output.result, output.folder, files)
    write_atomic(output.folder / SUMMARY_FILE, text)
    print()
    print(text, end="")
    return 0

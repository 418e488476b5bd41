"""``hiab-sim simulate``: validate a result in closed loop, the crane driven by simulated EMLA drives.

For each design of an ``hiab-sim optimize`` folder, one cycle of the study is simulated on the
dm-control environment of :mod:`hiab_sim.env` (MuJoCo multibody + PMSM drives with their current
loops and limits) under the cascade controller of :mod:`hiab_sim.control`. Written to ``--out``
(default: RESULT_DIR), each file atomically:

* ``simulation.json``: per design the closed-loop net electrical energy (each drive's DC input: int
  3/2 (v_d i_d + v_q i_q) dt with the EMLA file's inverter loss and holding brake, all drives;
  :mod:`hiab_sim.env.drive_losses`), the optimiser's predicted one and the planner's energy of the plan
  on a 5 ms grid, the TCP error (rms, max) to the study's reference,
  the fractions of time at the current and voltage limits, and ``bandwidth_check``: the
  controller's ``velocity_loop_bandwidth_Hz`` against the structure's ``first_natural_frequency_Hz``
  over the plan, ``bandwidth_margin`` = 1 - f_v / (f_1 / 3) (>= 0 holds;
  :mod:`hiab_sim.env.loop_design`), also printed at the end; with ``--payload-error`` also the
  nominal run and the extra energy the heavier end mass costs;
* ``closed_loop_*.png`` figures (:mod:`hiab_sim.env.figures`) and ``closed_loop.mp4`` (rendered
  through dm-control's ``Physics.render``, OSMesa; side by side when both designs run).

The table printed at the end is the one of docs/results/closed-loop.md.

``--plant realistic|ideal|FILE.yaml`` simulates the plant of :mod:`hiab_sim.env.plant` (default:
ideal, the planner's own model) and, when the plant has effects on, adds ``plant_effects`` to
``simulation.json`` (:mod:`hiab_sim.env.effects`: each effect alone and all together, both designs),
prints its table, writes ``effects.md`` (a five-line table, one column per variant, and the full one:
:func:`hiab_sim.env.effect_report.effect_markdown`) and ``closed_loop_plant_effects.png``. ``--cycles N`` runs
N cycles with the winding temperature carried over; the energies are the last cycle's.

A duty mix's result (``result.json`` ``tasks``) is simulated task by task: each design of each task
on the task's own plan (its motion, payload and duty), compared with the task's own energies of one
cycle (``tasks[k].<design>``), not with the mix's weighted sums; ``simulation.json`` holds ``tasks``
(per task its ``designs``) and ``mix`` (per design sum_k w_k E_k, closed loop against the result's),
the table a row per task and design, the figures and videos one set per task (``_task<k>`` before the
extension). The effect study (a plant with effects on) runs per task too, on the task's own plans
against its own energies: ``tasks[k].plant_effects``, ``effects_task<k>.md`` and
``closed_loop_plant_effects_task<k>.png``, its table printed per task; a mix's task is not re-planned
for the true masses (the re-planned prediction is that of a single-task study).

A machine file's result (:mod:`hiab_sim.machine`, e.g. the excavator) runs through
:mod:`hiab_sim.cli.simulate_machine`: the same report, plant and effect study, each chain's EMLA
drive on the machine's generic MJCF (:mod:`hiab_sim.env.machine_env`), ``closed_loop.mp4`` in the machine
file's dressing; the crane-only ``--payload-error`` (the crane's end-mass body) is refused.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from hiab_sim.cli.options import add_out_option
from hiab_sim.cli.simulate_summary import print_results, task_indices, task_runs_with_models, write_results
from hiab_sim.errors import InvalidInputError

#: Closed-loop checks: energy within this fraction of the prediction, TCP error rms and max [mm].
ENERGY_TOLERANCE = 0.02
TCP_RMS_MM = 2.0
TCP_MAX_MM = 5.0
PAYLOAD_TCP_MAX_MM = 20.0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "simulate",
        help="validate an optimisation result in closed loop (EMLA drives + tracking controller)",
        description=(
            "Simulate the study's cycle with the machine (crane file or machine file) built to each design, driven by "
            "PMSM drives (current loops, voltage and current limits, rotor inertia and friction) under a "
            "cascade tracking controller; compare the electrical energy with the optimiser's prediction. A duty "
            "mix's result runs per task and per design, each on the task's own plan against the task's own "
            "prediction, its figures and video suffixed _task0, _task1, ..."
        ),
    )
    parser.add_argument("result_dir", metavar="RESULT_DIR", help="folder written by 'hiab-sim optimize'")
    parser.add_argument("--design", choices=("initial", "optimal", "both"), default="both", help="default: both")
    parser.add_argument(
        "--payload-error",
        type=float,
        default=0.0,
        metavar="F",
        help="simulate an end mass (1 + F) times the planned one, F in [0, 2] (default: 0)",
    )
    parser.add_argument(
        "--plant",
        metavar="PLANT",
        default=None,
        help="plant effects: realistic, ideal or a plant YAML file (default: ideal, the planner's own model)",
    )
    parser.add_argument("--cycles", type=int, default=1, metavar="N", help="cycles per run, thermal state carried over")
    add_out_option(parser, "RESULT_DIR")
    parser.add_argument(
        "--no-video",
        action="store_true",
        help="skip closed_loop.mp4 (a duty mix: closed_loop_task0.mp4, ... one per task)",
    )
    parser.add_argument(
        "--no-figures",
        action="store_true",
        help="skip the closed_loop_*.png figures (a duty mix: one set per task, _task0, ...)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bars")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Simulate, write the results and print the table."""
    from hiab_sim.env.plan import read_plan

    error = args.payload_error
    if not (math.isfinite(error) and 0.0 <= error <= 2.0):
        raise InvalidInputError("--payload-error", error, "must lie in [0, 2] (relative end-mass error)")
    if args.cycles < 1:
        raise InvalidInputError("--cycles", args.cycles, "must be an integer >= 1")
    designs = ("initial", "optimal") if args.design == "both" else (args.design,)
    out = Path(args.out) if args.out else Path(args.result_dir)
    if out.exists() and not out.is_dir():
        raise InvalidInputError("--out", str(out), "must be a folder")
    from hiab_sim.env.machine_plan import is_machine_result
    from hiab_sim.env.plan import mix_tasks

    tasks = task_indices(mix_tasks(args.result_dir))
    if is_machine_result(args.result_dir):  # its plant: the machine file's realistic one, read there
        from hiab_sim.cli.simulate_machine import run_machine

        return run_machine(args, designs, out, tasks)
    from hiab_sim.env.plant import load_plant

    plant = load_plant(args.plant) if args.plant is not None else None
    plans = [read_plan(args.result_dir, design, task) for task in tasks for design in designs]  # bad input first
    out.mkdir(parents=True, exist_ok=True)
    if not args.no_video:
        from hiab_sim.render.backend import ffmpeg_path

        ffmpeg_path()

    from hiab_sim.env.validation import render_video, simulate_designs, simulation_report

    runs, nominal, physics = simulate_designs(
        plans, error, quiet=args.quiet, plant=plant, cycles=args.cycles, keep_physics=not args.no_video
    )
    report = simulation_report(args.result_dir, runs, nominal, emlas=plans[0].emlas)
    written, effects = write_results(args, report, runs, nominal, plant, designs, out)
    if not args.no_video:
        plan = plans[0]
        for suffix, of_task, drawn in task_runs_with_models(runs, physics):
            of_nominal = [run for run in nominal if run.task == of_task[0].task]
            video = render_video(
                out / f"closed_loop{suffix}.mp4",
                of_task,
                drawn,
                plan.crane,
                plan.emlas.battery,
                of_nominal or None,
                quiet=args.quiet,
            )
            written.append(video.name)
    for item in physics:
        item.free()
    print_results(report, effects)
    print(f"wrote {', '.join(written)} to {out}", file=sys.stderr)
    return 0

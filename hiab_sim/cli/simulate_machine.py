"""``hiab-sim simulate`` on a machine file's result: each design in closed loop on :mod:`hiab_sim.env.machine_env`.

The same ``simulation.json``, table, figures and closing lines as the crane's
(:mod:`hiab_sim.cli.simulate`): the EMLA drives' current dynamics per chain under the cascade
controller with the plan's feedforward, on the plant of ``--plant`` (the ideal one by default; the
effects of :mod:`hiab_sim.env.plant` on the machine's own parts, :mod:`hiab_sim.env.machine_env`)
for ``--cycles`` cycles, and with effects on the effect study of :mod:`hiab_sim.env.effects`
(``plant_effects``, its table and ``closed_loop_plant_effects.png``). What is built on the crane's
model is refused with one line (exit 2) naming it: ``--payload-error`` (the crane's end-mass body;
the plant's ``mismatch`` scales a machine's payload). ``closed_loop.mp4`` draws each design's simulation
model at its recorded states in the machine file's dressing (:mod:`hiab_sim.render.dress_machine`, on the
soil of the study's tasks where they cut one), the pivots the decision variables move marked.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from hiab_sim.errors import InvalidInputError

if TYPE_CHECKING:
    from hiab_sim.env.machine_plan import MachinePlan
    from hiab_sim.env.physics import CranePhysics
    from hiab_sim.env.rollout import ClosedLoopRun

#: What the report says of the energy boundary and the TCP error of a machine's closed loop.
MACHINE_ENERGY = (
    "closed loop: each drive's DC input over the cycle (int 3/2 (v_d i_d + v_q i_q) dt with the EMLA file's "
    "drive losses when they are on, hiab_sim.env.drive_losses), summed over the drives (the shared DC bus credits "
    "one drive's regeneration to the others; no battery); the prediction is the same sum of the plan's P_elec "
    "per drive"
)
MACHINE_TCP = (
    "distance of the simulated TCP to the study's TCP reference (x_tcp, y_tcp) in the machine's plane, placed at "
    "the TCP's out-of-plane coordinate z_tcp (the plane the TCP moves in)"
)
NO_STRUCTURE = "the EMLA file lacks screw or drive_stiffness data for the machine's natural frequencies"


def refuse_crane_only(args: argparse.Namespace) -> None:
    """One line naming what a machine file's closed loop does not simulate (exit 2 through the CLI)."""
    if args.payload_error != 0.0:
        raise InvalidInputError(
            "--payload-error",
            args.payload_error,
            "must be 0 for a machine file's result (the crane's end-mass body; --plant's mismatch scales a payload)",
        )


def run_machine(
    args: argparse.Namespace, designs: tuple[str, ...], out: Path, tasks: tuple[int | None, ...] = (None,)
) -> int:
    """Simulate every design (of every task) of a machine file's result, write ``simulation.json`` (and figures), print.

    ``--plant realistic`` is the machine file's own realistic plant where it names one
    (:func:`hiab_sim.env.plant.load.machine_plant`). ``tasks``: a duty mix's task indices, each task's
    designs on the task's own plan, or (None,) for a single-task result.
    """
    from hiab_sim.cli.simulate_summary import print_results, task_runs_with_models, write_results
    from hiab_sim.design_report.simulation_table import run_groups
    from hiab_sim.env.machine_env import run_machine_closed_loop
    from hiab_sim.env.machine_plan import read_machine_plan
    from hiab_sim.env.plant.load import machine_plant
    from hiab_sim.env.validation import simulation_report

    refuse_crane_only(args)
    plans = [read_machine_plan(args.result_dir, design, task) for task in tasks for design in designs]  # fails first
    plant = None if args.plant is None else machine_plant(args.plant, plans[0].machine.realistic_plant)
    if not args.no_video:
        from hiab_sim.render.backend import ffmpeg_path

        ffmpeg_path()  # a missing ffmpeg fails before the simulation
    out.mkdir(parents=True, exist_ok=True)
    runs, models = [], []
    try:
        for plan in plans:
            run, physics = run_machine_closed_loop(plan, plant=plant, cycles=args.cycles)
            runs.append(run)
            if args.no_video:  # nothing to draw: one Physics alive at a time
                physics.free()
            else:
                models.append(physics)
        report = simulation_report(args.result_dir, runs, [], emlas=plans[0].emlas)
        settings = report["settings"]
        assert isinstance(settings, dict)
        settings.update(energy=MACHINE_ENERGY, tcp_error=MACHINE_TCP, machine=plans[0].machine.name)
        settings["tcp_load"] = "the plan's TCP force F(t) of the run's task, applied at site tcp"
        groups = list(run_groups(report))
        for group in groups:
            for entry in group.designs.values():
                if entry["bandwidth_check"].get("first_natural_frequency_Hz") is None:
                    entry["bandwidth_check"]["note"] = NO_STRUCTURE
        written, effects = write_results(args, report, runs, [], plant, designs, out)
        if not args.no_video:
            for suffix, of_task, drawn in task_runs_with_models(runs, models):
                written.append(_video(args, out / f"closed_loop{suffix}.mp4", plans, of_task, drawn).name)
    finally:
        for physics in models:
            physics.free()
    print_results(report, effects)
    for group in groups:
        opened = "" if group.task is None else f"{group.task}, "
        for design, entry in group.designs.items():
            if entry.get("battery_energy_difference_percent") is not None:
                print(
                    f"{opened}{design}: battery energy over the cycle {entry['battery_energy_J']:.1f} J "
                    f"closed loop against {entry['predicted_battery_energy_J']:.1f} J planned "
                    f"({entry['battery_energy_difference_percent']:+.2f} %; without a duty period's rest, "
                    "which optimize's battery energy per duty period holds)."
                )
    print(f"wrote {', '.join(written)} to {out}", file=sys.stderr)
    return 0


def _video(
    args: argparse.Namespace,
    path: Path,
    plans: list[MachinePlan],
    runs: list[ClosedLoopRun],
    models: list[CranePhysics],
) -> Path:
    """``closed_loop.mp4`` (a duty mix: per task): the runs on their simulation models in the machine's dressing."""
    from hiab_sim.env.validation import closed_loop_video
    from hiab_sim.render.dress_machine import machine_file_dress, moved_pivots
    from hiab_sim.render.machine_playback import study_ground
    from hiab_sim.results.read import read_result

    ground = study_ground(read_result(args.result_dir).study)
    machines = {plan.design: plan.machine for plan in plans}
    marks = moved_pivots(plans[0].machine, [machine.design_values() for machine in machines.values()])
    return closed_loop_video(
        path,
        runs,
        models,
        lambda model, run: machine_file_dress(model, machines[run.design], ground),
        marks,
        plans[0].emlas.battery,
        quiet=args.quiet,
        load="load",
    )

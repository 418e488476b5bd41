"""Closed-loop validation of a result: simulate designs, report against the prediction, render a video.

Used by ``hiab-sim simulate`` (:mod:`hiab_sim.cli.simulate`); see there for the outputs. A duty mix's
result is simulated task by task, each design of each task on the task's own plan, and each run is
compared with its task's own prediction (:mod:`hiab_sim.env.plan`): ``simulation.json`` then holds
``tasks`` (per task its name, weight and ``designs``) where a single-task result holds ``designs``,
and ``mix``: per design the weighted sum over the tasks, sum_k w_k E_k, closed loop (at the planned
end mass) against the result's own (``result.json`` ``<design>.net_electrical_energy_J``, per hour where the weights are
cycles per hour).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from hiab_sim.arrays import Array
from hiab_sim.control.cascade import CascadeGains
from hiab_sim.crane.description import Crane
from hiab_sim.emla.battery import BatteryParams
from hiab_sim.emla.config import EmlaSet
from hiab_sim.env import CURRENT_BANDWIDTH_HZ, PHYSICS_TIMESTEP
from hiab_sim.env.closed_loop_battery import (
    BATTERY_NOTE,
    battery_entry,
    battery_notes,
    predicted_cycle_battery_energy,
)
from hiab_sim.env.physics import CranePhysics
from hiab_sim.env.plan import DesignPlan, mix_tasks, read_plan
from hiab_sim.env.plant.config import Plant
from hiab_sim.env.rollout import ClosedLoopRun, run_closed_loop
from hiab_sim.percent import change_percent
from hiab_sim.results.schema import TaskResult
from hiab_sim.terminal import progress_wanted

#: Video frame rate [1/s] and the size of one design's viewport (width, height) [px].
FPS = 30.0
VIEWPORT = (480, 480)


def simulate_designs(
    plans: Sequence[DesignPlan],
    payload_error: float,
    quiet: bool = False,
    plant: Plant | None = None,
    cycles: int = 1,
    keep_physics: bool = True,
) -> tuple[list[ClosedLoopRun], list[ClosedLoopRun], list[CranePhysics]]:
    """Run every plan at ``payload_error`` (and, when it is not 0, nominally too) on ``plant`` for ``cycles``.

    ``plans``: one per design (:func:`hiab_sim.env.plan.read_plan`), a duty mix's every design of each
    task in task order. ``keep_physics`` False (no video to render): each run's Physics is freed as
    soon as the run ends, so that one lives at a time however many tasks and designs run.

    Returns:
        The runs at ``payload_error``, the nominal runs (empty when payload_error is 0) and the
        Physics of the first list (for rendering; free them when done), empty without ``keep_physics``.

    """
    runs: list[ClosedLoopRun] = []
    nominal: list[ClosedLoopRun] = []
    physics: list[CranePhysics] = []
    for plan in plans:
        design = plan.design
        conditions = [payload_error] if payload_error == 0.0 else [0.0, payload_error]
        for error in conditions:
            label = design if error == 0.0 else f"{design} end mass +{100 * error:g} %"
            label = label if plan.task is None else f"{plan.task}: {label}"
            with tqdm(
                total=1, desc=label, unit="step", disable=quiet or not progress_wanted(), file=sys.stderr, leave=False
            ) as bar:

                def progress(done: int, total: int, bar: tqdm = bar) -> None:
                    if bar.total != total:
                        bar.reset(total=total)
                    if done % 50 == 0 or done == total:
                        bar.n = done
                        bar.refresh()

                run, item = run_closed_loop(plan, error, progress=progress, plant=plant, cycles=cycles)
            (runs if error == payload_error else nominal).append(run)
            if keep_physics and error == payload_error:
                physics.append(item)
            else:
                item.free()
    return runs, nominal, physics


def simulation_report(
    result_dir: str | Path, runs: list[ClosedLoopRun], nominal: list[ClosedLoopRun], emlas: EmlaSet | None = None
) -> dict[str, object]:
    """The content of ``simulation.json``; ``emlas`` the runs' EMLA set (None: the crane result's, read from it).

    Every run's entry carries its battery energy (:func:`hiab_sim.env.closed_loop_battery.battery_entry`)
    against the result's battery energy of one cycle (a duty mix's task: the task's own); a nominal run's
    against the same plan. Runs of a duty mix's tasks are grouped per task (module docstring).
    """
    tasks = mix_tasks(result_dir) if any(run.task is not None for run in runs) else ()
    if emlas is None and runs:
        emlas = read_plan(result_dir, runs[0].design, 0 if tasks else None).emlas
    report: dict[str, object] = {"result_dir": str(Path(result_dir).resolve())}
    if tasks:
        groups = []
        for k, task in enumerate(tasks):
            of_task = [run for run in runs if run.task == task.name]
            if of_task:
                predicted = predicted_cycle_battery_energy(result_dir, k)
                entries = _design_entries(of_task, [n for n in nominal if n.task == task.name], emlas, predicted)
                groups.append({"task": task.name, "weight": task.weight, "designs": entries, **_cheaper(of_task)})
        report["tasks"] = groups
        report["mix"] = _mix_entry(result_dir, nominal or runs, tasks)  # at the planned end mass
    else:
        predicted = predicted_cycle_battery_energy(result_dir) if runs else {}
        report["designs"] = _design_entries(runs, nominal, emlas, predicted)
    gains = runs[0].gains if runs else CascadeGains()
    report.update({
        "settings": {
            "physics_timestep_s": PHYSICS_TIMESTEP,
            "control_timestep_s": float(runs[0].time[1] - runs[0].time[0]),
            "current_loop_bandwidth_Hz": CURRENT_BANDWIDTH_HZ,
            "cascade_bandwidths_rad_per_s": {
                "position": gains.position,
                "velocity": gains.velocity,
                "integral": gains.integral,
            },
            "energy": "closed loop: each drive's DC input over the cycle (int 3/2 (v_d i_d + v_q i_q) dt with the "
            "EMLA file's inverter loss and holding brake, hiab_sim.env.drive_losses), summed over the drives",
            "tcp_error": "distance of the simulated TCP to the study's TCP reference at the same time",
            "battery_energy": BATTERY_NOTE,
            "plant": runs[0].plant if runs else "ideal",
        },
    })  # fmt: skip
    if tasks:
        settings = report["settings"]
        assert isinstance(settings, dict)
        settings["tasks"] = MIX_NOTE
    boundary = energy_boundary(emlas) if emlas is not None else None
    if boundary is not None:
        report["energy_boundary"] = boundary
    if not tasks:
        report.update(_cheaper(runs))
    return report


#: What ``simulation.json`` says of a duty mix's runs.
MIX_NOTE = (
    "a duty mix's result: each design of each task simulated on the task's own plan (trajectory.npz "
    "task<k>_*, its payload and duty) and compared with the task's own prediction of one cycle (result.json "
    "tasks[k].<design>); mix: per design sum_k w_k E_k over the tasks, closed loop against the result's "
    "<design>.net_electrical_energy_J (per hour where the weights are cycles per hour)"
)


def _design_entries(
    runs: list[ClosedLoopRun], nominal: list[ClosedLoopRun], emlas: EmlaSet | None, predicted: dict[str, float]
) -> dict[str, object]:
    """Per design: the run's summary, its battery energy against ``predicted`` [J] and, with one, its nominal run."""
    designs: dict[str, object] = {}
    for run in runs:
        entry = run.summary()
        if emlas is not None:
            entry.update(battery_entry(run, emlas.battery, predicted.get(run.design)))
        match = next((n for n in nominal if n.design == run.design), None)
        if match is not None:
            nominal_entry = match.summary()
            if emlas is not None:
                nominal_entry.update(battery_entry(match, emlas.battery, predicted.get(match.design)))
            entry["nominal"] = nominal_entry
            entry["extra_energy_J"] = run.net_energy - match.net_energy
            entry["extra_energy_vs_predicted_J"] = run.net_energy - run.predicted_net_energy
        designs[run.design] = entry
    return designs


def _cheaper(runs: list[ClosedLoopRun]) -> dict[str, bool]:
    """``optimal_below_initial``: whether the optimal design's closed loop uses less energy (with both designs run)."""
    by_design = {run.design: run for run in runs}
    if {"initial", "optimal"} <= by_design.keys():
        return {"optimal_below_initial": by_design["optimal"].net_energy < by_design["initial"].net_energy}
    return {}


def _mix_entry(result_dir: str | Path, runs: list[ClosedLoopRun], tasks: Sequence[TaskResult]) -> dict[str, object]:
    """Per design run on every task: sum_k w_k E_k closed loop and the result's weighted sum [J] (module docstring)."""
    from hiab_sim.results.read import read_result

    result = read_result(result_dir)
    mix: dict[str, object] = {}
    for design in dict.fromkeys(run.design for run in runs):
        energy = {run.task: run.net_energy for run in runs if run.design == design}
        if not all(task.name in energy for task in tasks):
            continue
        closed = float(sum(task.weight * energy[task.name] for task in tasks))
        planned = float((result.optimal if design == "optimal" else result.initial).net_electrical_energy_J)
        mix[design] = {
            "net_electrical_energy_J": closed,
            "predicted_net_electrical_energy_J": planned,
            "energy_difference_percent": change_percent(planned, closed),
        }
    return mix


def energy_boundary(emlas: EmlaSet) -> str | None:
    """The boundary at which the prediction and the closed loop are compared, or None for the paper's drive.

    Both count the EMLA file's drive losses (:mod:`hiab_sim.emla.losses`) when any is on: the closed-loop
    drives carry them through the planner's own functions (:mod:`hiab_sim.env.drive_losses`), so the two
    energies are each drive's DC input, inverter loss and brake coil included.
    """
    lossy = [p for p in emlas if p.losses.transmission_on or p.losses.inverter_on or p.losses.brake_on]
    if not lossy:
        return None
    described = sorted({p.losses.describe() for p in lossy})
    text = (
        "both energies are the drives' DC inputs with the EMLA file's "
        + " | ".join(described)
        + f" ({', '.join(p.name for p in lossy)}), in the closed loop through the planner's loss functions"
    )
    if any(p.losses.brake_on for p in lossy):
        text += (
            "; the holding brake enters the energy only, in the planner's smooth form (the simulated motor keeps "
            "holding below the brake speed)"
        )
    return text


def closed_loop_frame_times(duration: float) -> Array:
    """The closed-loop video's frame instants [s]: 0, 1/FPS, ... and ``duration`` itself last.

    Real time at ``FPS``; when ``duration`` is not a whole number of frames the last frame is the
    cycle's end (less than one frame after the one before), so it shows the cycle's total energy.
    """
    at = np.arange(int(np.floor(duration * FPS + 1e-9)) + 1) / FPS
    return at if duration - at[-1] < 1e-9 else np.append(at, duration)


def render_video(
    path: Path,
    runs: list[ClosedLoopRun],
    physics: list[CranePhysics],
    crane: Crane,
    battery: BatteryParams,
    nominal: list[ClosedLoopRun] | None = None,
    quiet: bool = False,
) -> Path:
    """Render a crane file's closed-loop runs in the playback's visual language (:mod:`hiab_sim.render`).

    One panel per end-mass condition (the planned mass when ``nominal`` runs are given, then the
    runs' own), each overlaying the optimal design (opaque) on the initial one (ghost), the
    machine dressed from ``crane``, with the time and each design's battery energy so far of the
    cycle against its total [kJ] (:func:`hiab_sim.env.closed_loop_battery.battery_notes`, the
    battery ``battery`` of the EMLA file; the total is ``simulation.json``'s ``battery_energy_J``).
    A nominal run is drawn with its design's model of ``physics`` (the end-mass error changes
    inertia, not geometry).
    """
    from hiab_sim.render.dress import machine_dress

    marks = tuple(f"{chain.name}_base_pivot" for chain in crane.chains)
    return closed_loop_video(
        path, runs, physics, lambda model, run: machine_dress(model, crane), marks, battery, nominal, quiet
    )


def closed_loop_video(
    path: Path,
    runs: list[ClosedLoopRun],
    physics: list[CranePhysics],
    dress: Callable[[Any, ClosedLoopRun], Any],
    marks: tuple[str, ...],
    battery: BatteryParams,
    nominal: list[ClosedLoopRun] | None = None,
    quiet: bool = False,
    load: str = "end mass",
) -> Path:
    """The closed-loop video of any machine: ``dress(model, run)`` draws a run's model, ``marks`` names its pivots.

    The panels, overlay, captions and battery notes of :func:`render_video`; each run is drawn on
    its own simulation model (``physics``, in ``runs``' order) at its recorded qpos. ``load`` names
    what ``payload_error`` scales in the captions.
    """
    from hiab_sim.render.backend import video_sink
    from hiab_sim.render.decor import design_rgba
    from hiab_sim.render.frames import Design, PlaybackRenderer

    width, height = VIEWPORT
    at = closed_loop_frame_times(min(run.time[-1] for run in runs))
    frames = len(at)
    models = {run.design: item.model.ptr for run, item in zip(runs, physics, strict=True)}
    panels = [nominal, runs] if nominal else [runs]

    def design(run: ClosedLoopRun) -> Design:
        index = np.clip(np.searchsorted(run.time, at), 0, len(run.time) - 1)
        notes = battery_notes(run, battery, at)
        mass = f"planned {load}" if run.payload_error == 0 else f"{load} +{100 * run.payload_error:g} %"
        caption = f"{run.design}, {mass}" if run.design != "initial" else "initial (ghost)"
        model = models[run.design]
        return Design(
            run.design, model, run.qpos[index], design_rgba(run.design), caption, notes,
            dress=dress(model, run), marks=marks,
        )  # fmt: skip

    renderers = []
    try:
        for panel in panels:
            ordered = sorted(panel, key=lambda run: run.design != "optimal")  # the optimal design opaque
            renderers.append(PlaybackRenderer([design(run) for run in ordered], None, (width, height), "overlay"))
        with video_sink(path, (width * len(renderers), height), FPS) as sink:
            for frame in tqdm(
                range(frames),
                desc="video",
                unit="frame",
                disable=quiet or not progress_wanted(),
                file=sys.stderr,
                leave=False,
            ):
                sink.add(np.hstack([renderer.frame(frame) for renderer in renderers]))
    finally:
        for renderer in renderers:
            renderer.close()
    return path

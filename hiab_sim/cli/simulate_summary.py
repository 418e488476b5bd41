"""What ``hiab-sim simulate`` writes and prints for a crane's or a machine's closed loop: files, tables, the answer."""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from hiab_sim.env.physics import CranePhysics
    from hiab_sim.env.plant.config import Plant
    from hiab_sim.env.rollout import ClosedLoopRun


def task_indices(tasks: Sequence[object]) -> tuple[int | None, ...]:
    """The task indices a result's plans are read with: 0 .. n-1 of a duty mix's n tasks, (None,) for a single task."""
    return tuple(range(len(tasks))) if tasks else (None,)


def task_runs(runs: list[ClosedLoopRun]) -> list[tuple[str, list[ClosedLoopRun]]]:
    """The runs of each task with the suffix of its files: ``""`` for a single task, ``_task<k>`` for a mix's task k.

    ``runs`` hold every task of a duty mix's result, in the result's order (as :func:`task_indices` reads them).
    """
    from hiab_sim.design_report.simulation_table import task_suffix

    names = list(dict.fromkeys(run.task for run in runs))
    if names == [None]:
        return [(task_suffix(None), runs)]
    return [(task_suffix(k), [run for run in runs if run.task == name]) for k, name in enumerate(names)]


def task_runs_with_models(
    runs: list[ClosedLoopRun], models: Sequence[CranePhysics]
) -> list[tuple[str, list[ClosedLoopRun], list[CranePhysics]]]:
    """:func:`task_runs` with each run's simulation model beside it (``models`` in the order of ``runs``)."""
    model_of = {id(run): model for run, model in zip(runs, models, strict=True)}
    return [(suffix, of_task, [model_of[id(run)] for run in of_task]) for suffix, of_task in task_runs(runs)]


def write_results(
    args: argparse.Namespace,
    report: dict[str, object],
    runs: list[ClosedLoopRun],
    nominal: list[ClosedLoopRun],
    plant: Plant | None,
    designs: tuple[str, ...],
    out: Path,
) -> tuple[list[str], list[TaskEffects]]:
    """Run the effect study (a plant with effects on); write ``simulation.json``, ``effects.md``, the figures.

    A duty mix's effect study runs per task on the task's own plans (``tasks[k].plant_effects``,
    ``effects_task<k>.md``, ``closed_loop_plant_effects_task<k>.png``); a single task's is
    ``plant_effects``, ``effects.md`` and ``closed_loop_plant_effects.png``. Returns the names of the
    files written and the effect studies (none without effects on), which ``report`` holds too.
    """
    effects = _effect_studies(args, report, plant, designs)
    from hiab_sim.atomic_io import write_atomic

    write_atomic(out / "simulation.json", json.dumps(report, indent=2) + "\n")
    written = ["simulation.json"]
    from hiab_sim.env.effect_report import write_effect_markdown

    for entry in effects:
        written.append(write_effect_markdown(out / f"effects{entry.suffix}.md", entry.study).name)
    if not args.no_figures:
        from hiab_sim.env.figures import write_figures

        for suffix, of_task in task_runs(runs):
            of_nominal = [run for run in nominal if run.task == of_task[0].task]
            written += [p.name for p in write_figures(out, of_task, of_nominal, suffix)]
        from hiab_sim.env.effect_report import effect_figure

        for entry in effects:
            figure = out / f"closed_loop_plant_effects{entry.suffix}.png"
            written.append(effect_figure(figure, entry.study).name)
    return written, effects


@dataclass(frozen=True)
class TaskEffects:
    """One effect study: the suffix of its files (``""``, ``_task<k>``), its task (None: a single task), the study."""

    suffix: str
    task: str | None
    study: dict[str, object]


def _effect_studies(
    args: argparse.Namespace, report: dict[str, object], plant: Plant | None, designs: tuple[str, ...]
) -> list[TaskEffects]:
    """The effect study of every task (a duty mix: each on its own plans), put into ``report``; none without effects."""
    if plant is None or not plant.enabled:
        return []
    from hiab_sim.design_report.simulation_table import task_suffix
    from hiab_sim.env.effects import attach_replanned, effect_study, replanned_predictions

    groups = report.get("tasks")
    if not isinstance(groups, list):
        study = effect_study(args.result_dir, plant, args.cycles, designs, quiet=args.quiet)
        report["plant_effects"] = study
        return [TaskEffects(task_suffix(None), None, study)]
    out = []
    for k, group in enumerate(groups):  # every task of the result, in its order (simulation_report)
        study = effect_study(args.result_dir, plant, args.cycles, designs, quiet=args.quiet, replan=False, task=k)
        group["plant_effects"] = study
        out.append(TaskEffects(task_suffix(k), str(group["task"]), study))
    if plant.mismatch.enabled:  # the mix solved again once at the true masses: each task's share of its optimum
        for k, replanned in enumerate(replanned_predictions(args.result_dir, plant)):
            attach_replanned(out[k].study, replanned)
    return out


def print_results(report: dict[str, object], effects: Sequence[TaskEffects]) -> None:
    """Print the table, each effect study's table and lines (a duty mix's: per task) and the closing lines."""
    from hiab_sim.design_report.simulation_table import markdown_table

    print(markdown_table(report))
    from hiab_sim.env.effect_report import effect_lines, effect_table

    for of_task in effects:
        print()
        if of_task.task is not None:
            print(f"Plant effects, task {of_task.task} (its own plans and energies):")
        print(effect_table(of_task.study))
        for line in effect_lines(of_task.study):
            print(line)
    print()
    for line in closing_lines(report):
        print(line)


def closing_lines(report: dict[str, object]) -> list[str]:
    """The answer in words: per design (and task) the closed loop against the plan, what a heavier end mass costs.

    A duty mix's also gives its weighted sum over the tasks per design against the result's (``mix``).
    """
    from hiab_sim.design_report.simulation_table import run_groups

    lines = []
    for group in run_groups(report):
        lines += _design_lines(group.designs, "" if group.task is None else f"{group.task}, ")
    mix = report.get("mix")
    for design, entry in mix.items() if isinstance(mix, dict) else ():
        lines.append(
            f"{design}, the duty mix (sum of weight x energy over the tasks): {entry['net_electrical_energy_J']:.1f} J "
            f"closed loop against {entry['predicted_net_electrical_energy_J']:.1f} J planned "
            f"({entry['energy_difference_percent']:+.2f} %)."
        )
    boundary = report.get("energy_boundary")
    if boundary is not None:
        lines.append(f"Energy boundary: {boundary}.")
    return lines


def _design_lines(designs: Mapping[str, Any], task: str) -> list[str]:
    """Per design of ``designs`` the closing line and its bandwidth line, each opened by ``task``."""
    from hiab_sim.design_report.simulation_table import entry_runs

    lines = []
    for design, entry in designs.items():
        rows = entry_runs(entry)
        planned = rows[0]
        fine = planned.get("energy_difference_to_5ms_grid_percent")
        text = (
            f"{task}{design}: the closed loop uses {planned['energy_difference_percent']:+.2f} % energy "
            "against the plan"
            + ("" if fine is None else f" ({fine:+.2f} % against the planner's energy of the plan on a 5 ms grid)")
            + f", tracking within {planned['tcp_error_mm']['max']:.2f} mm"
        )
        if len(rows) == 2:
            heavy = rows[1]
            text += (
                f"; with the end mass +{100 * heavy['payload_error']:g} % it needs {heavy['extra_energy_J']:.0f} J "
                f"more ({heavy['energy_difference_percent']:+.2f} % against the plan: the heavier load's energy, "
                f"not a failure), tracking within {heavy['tcp_error_mm']['max']:.2f} mm"
            )
        lines.append(text + ".")
        check = planned.get("bandwidth_check") or {}
        if check:
            lines.append(bandwidth_line(f"{task}{design}", check))
    return lines


def bandwidth_line(design: str, check: Mapping[str, Any]) -> str:
    """One line of a run's ``bandwidth_check``: f_v against f_1, their ratio and whether 1 - f_v / (f_1 / 3) >= 0."""
    f_v = float(check["velocity_loop_bandwidth_Hz"])
    margin, f_1 = check.get("bandwidth_margin"), check.get("first_natural_frequency_Hz")
    if margin is None or f_1 is None:
        reason = check.get("note", "the EMLA file has no screw and drive_stiffness data for the natural frequencies")
        return f"{design}: velocity loop {f_v:.2f} Hz; no bandwidth check ({reason})."
    margin, f_1 = float(margin), float(f_1)
    verdict = (
        "holds: 1 - f_v / (f_1 / 3) >= 0"
        if margin >= 0.0
        else f"FAILS 1 - f_v / (f_1 / 3) >= 0: too close to the structure's resonance, at most {f_1 / 3.0:.2f} Hz"
    )
    return (
        f"{design}: velocity loop {f_v:.2f} Hz against the structure's lowest natural frequency {f_1:.2f} Hz on "
        f"the plan (ratio {f_v / f_1:.2f}, at most 1/3): bandwidth_margin {margin:+.2f} ({verdict})."
    )

"""Figures of an optimisation result (Agg backend, written atomically as PNG).

Seed figures: objective per iteration (Fig. ``Objective_function``), decision variables per
iteration (Figs. ``Decision_variables_1/2``), initial vs optimal structure (Fig.
``Initial_Structure_Modified``), the crane with the spiral (Fig. ``hiab``); plus actuator force,
velocity and electrical power over time, operating points on the efficiency maps, and the energy
breakdown, initial vs optimal.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.emla import EmlaSet
from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.results.analysis_sections import Sensitivity
from hiab_sim.results.design_values import DesignValues, crane_lengths
from hiab_sim.results.schema import HistoryRow, Result
from hiab_sim.study.figures.design import (
    cumulative_energy,
    decision_panels,
    draw_crane,
    energy_bars,
    sensitivity_bars,
    structure_overlay,
)
from hiab_sim.study.figures.energy import hydraulic_figure
from hiab_sim.study.report.design_check import DesignCheck
from hiab_sim.style import colour

__all__ = ["draw_crane", "write_figures"]

#: What each objective is, in words, for axis labels.
OBJECTIVE_WORDS = {
    "costf2": "squared-power cost (the seed paper's costf2, W^2 s)",
    "battery_energy": "battery energy per cycle (J)",
}


def objective_figure(history: tuple[HistoryRow, ...], path: Path, objective: str = "costf2") -> None:
    """The objective and the largest violation per SQP iteration, one panel each (seed Fig. Objective_function).

    ``objective`` names what was minimised (the result's ``energy.objective``); the top panel shows
    it relative to its value at the start, so the saving reads off the axis.
    """
    fig = new_figure((6.5, 5.0))
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2.0, 1.0))
    it = [h.iteration for h in history]
    words = OBJECTIVE_WORDS.get(objective, objective.replace("_", " "))
    top.plot(it, [h.scaled_cost for h in history], "o-", color=colour("optimal"), markersize=3, label=words)
    top.set_ylabel("objective / its value at the start")
    top.set_title("How the optimiser got there: objective and constraint violation per iteration", fontsize=10)
    top.legend(fontsize=8)
    top.grid(alpha=0.3)
    bottom.semilogy(
        it, [max(h.max_violation, 1e-16) for h in history], ".--", color="0.35", markersize=3,
        label="largest constraint violation (scaled: 1 = a whole tracking band or limit)",
    )  # fmt: skip
    bottom.set_ylabel("largest violation")
    bottom.set_xlabel("SQP iteration")
    bottom.legend(fontsize=7)
    bottom.grid(alpha=0.3)
    save_png(fig, path)


def decision_figure(
    history: tuple[HistoryRow, ...],
    indices: Sequence[int],
    labels: Sequence[str],
    name: str,
    path: Path,
    low: np.ndarray,
    up: np.ndarray,
) -> None:
    """One chain's decision variables per iteration with the bounds shaded (seed Figs. Decision_variables_1/2)."""
    fig = new_figure((6.5, 2.0 * len(indices)))
    axes = fig.subplots(len(indices), 1, sharex=True, squeeze=False)[:, 0]
    decision_panels(axes, history, indices, labels, low, up)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"Decision variables of the {name} chain (grey: outside the bounds)")
    save_png(fig, path)


def structure_figure(
    crane: Crane,
    designs: dict[str, LinkLengths],
    pose: np.ndarray,
    path: Path,
    label: str,
    most_loaded: tuple[str, float] | None = None,
    over: str = "the motion",
) -> None:
    """Both structures overlaid in one pose, pivot shifts dimensioned (seed Fig. Initial_Structure_Modified).

    ``most_loaded``: the optimal design's most loaded pin and its peak force [N] over ``over``, marked.
    """
    fig = new_figure((8.0, 6.4))
    structure_overlay(fig.add_subplot(), crane, designs, pose, label, most_loaded, over)
    save_png(fig, path)


def spiral_figure(
    crane: Crane,
    lengths: LinkLengths,
    joints: np.ndarray,
    ref: np.ndarray,
    tcp: np.ndarray,
    path: Path,
    time: np.ndarray | None = None,
) -> None:
    """The crane at five poses, light to dark in time order, with the reference path (seed Fig. hiab)."""
    fig = new_figure((7.0, 5.2))
    ax = fig.add_subplot()
    picks = np.linspace(0, len(joints) - 1, 5).astype(int)
    shades = [0.25, 0.4, 0.55, 0.75, 1.0]
    centre = ref[:, :2].mean(axis=0)
    labels: list[tuple[np.ndarray, list[str]]] = []  # poses whose tool points coincide share one label
    for idx, alpha in zip(picks, shades, strict=True):
        draw_crane(ax, crane, lengths, joints[idx], colour("optimal"), alpha=alpha)
        when = f"{time[idx]:.1f} s" if time is not None else f"sample {idx}"
        for point, texts in labels:
            if np.hypot(*(point - tcp[idx, :2])) < 0.02:
                texts.append(when)
                break
        else:
            labels.append((tcp[idx, :2], [when]))
    for point, texts in labels:
        away = point - centre
        away = away / max(float(np.hypot(*away)), 1e-9)
        ax.annotate(
            "t = " + " and ".join(texts), (float(point[0]), float(point[1])), xytext=(34 * away[0], 34 * away[1]),
            textcoords="offset points", fontsize=8,
            ha="center", va="center", color="0.1", arrowprops={"arrowstyle": "-", "color": "0.4", "linewidth": 0.6},
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.85},
        )  # fmt: skip
    ax.plot(ref[:, 0], ref[:, 1], "-", color=colour("reference"), linewidth=2, label="reference path of the tool")
    ax.plot(tcp[:, 0], tcp[:, 1], "--", color=colour("optimal"), linewidth=1, label="tool path of the optimal design")
    ax.annotate(
        "", (float(tcp[min(len(tcp) - 1, 8), 0]), float(tcp[min(len(tcp) - 1, 8), 1])),
        xytext=(float(tcp[0, 0]), float(tcp[0, 1])),
        arrowprops={"arrowstyle": "->", "color": colour("optimal"), "linewidth": 1.5},
    )  # fmt: skip
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("horizontal distance from the column [m]")
    ax.set_ylabel("height above the column base [m]")
    ax.legend(loc="lower left", fontsize=8)
    ax.set_title("The optimal design following the path (five poses, darker = later)", fontsize=10)
    save_png(fig, path)


def actuator_figure(time: np.ndarray, checks: dict[str, DesignCheck], path: Path) -> None:
    """Force, velocity and electrical power per actuator over time, initial vs optimal."""
    names = checks["initial"].actuator_names
    fig = new_figure((4.0 * len(names), 8.0))
    axes = fig.subplots(3, len(names), sharex=True, squeeze=False)
    for name in ("initial", "optimal"):
        ev = checks[name].evaluation
        for i, act in enumerate(names):
            axes[0, i].plot(time, ev.actuators.force[:, i] / 1e3, color=colour(name), label=name)
            axes[1, i].plot(time, ev.actuators.velocity[:, i], color=colour(name))
            axes[2, i].plot(time, ev.power[:, i] / 1e3, color=colour(name))
            axes[0, i].set_title(act)
    for i in range(len(names)):
        axes[2, i].set_xlabel("time [s]")
    axes[0, 0].set_ylabel("force f_x [kN]")
    axes[1, 0].set_ylabel("velocity v_x [m/s]")
    axes[2, 0].set_ylabel("electrical power [kW]")
    axes[0, 0].legend()
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    save_png(fig, path)


def efficiency_figure(emlas: EmlaSet, checks: dict[str, DesignCheck], path: Path) -> None:
    """Operating points (initial, optimal) over each actuator's efficiency map."""
    from hiab_sim.emla.maps import EFFICIENCY_LABEL, efficiency_map, plot_efficiency_map

    fig = new_figure((5.6 * len(emlas) + 1.0, 6.0))
    axes = fig.subplots(1, len(emlas), squeeze=False)[0]
    losses = {p.losses.describe() for p in emlas}
    shared = len(losses) == 1  # the same drive losses on every map: named once, over the figure
    filled = None
    for i, (ax, params) in enumerate(zip(axes, emlas, strict=True)):
        emap = efficiency_map(params, n_force=81, n_velocity=81)
        ini = checks["initial"].evaluation.actuators
        opt = checks["optimal"].evaluation.actuators
        designs = {"initial": (ini.force[:, i], ini.velocity[:, i]), "optimal": (opt.force[:, i], opt.velocity[:, i])}
        plot_efficiency_map(emap, ax=ax, designs=designs, losses_in_title=not shared, colorbar=False)
        filled = ax.collections[0] if filled is None else filled
        if i > 0:  # one legend for the three maps: they share every entry
            legend = ax.get_legend()
            if legend is not None:
                legend.remove()
    if filled is not None:  # one colour bar: the maps share their levels and colours
        fig.colorbar(filled, ax=list(axes), label=EFFICIENCY_LABEL, shrink=0.9)
    if shared:
        fig.suptitle(next(iter(losses)), fontsize=9)
    save_png(fig, path)


def drive_train_energy(emlas: EmlaSet, check: DesignCheck, time: np.ndarray) -> float:
    """What the breakdown's parts leave out with the EMLA file's drive losses on [J], summed over the actuators.

    The screw and gearbox loss, the inverter loss, the brake coil's power and the load power the engaged
    brake carries (negative), integrated over ``time`` (the fine grid) at the breakdown's own operating
    points (:func:`hiab_sim.study.report.design_check.design_summary`: the same call of
    :func:`hiab_sim.emla.operating_point`), so that mechanical + copper + rotor friction + screw viscous +
    inertial + this = the breakdown's electrical energy; 0 for the paper's drive.
    """
    from hiab_sim.emla import operating_point
    from hiab_sim.quadrature import trapezoid

    act = check.evaluation.actuators
    total = 0.0
    for i, params in enumerate(emlas):
        op = operating_point(params, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
        total += float(
            trapezoid(op.transmission_loss + op.inverter_loss + op.brake_coil_power + op.brake_held_power, time)
        )
    return total


def energy_figure(
    time: np.ndarray, checks: dict[str, DesignCheck], path: Path, emlas: EmlaSet, hot_windings: bool = False
) -> None:
    """Where the energy goes (the breakdown's parts, the drive train's, their total) and the cumulative net energy.

    Both charts are the motors' net electrical energy over the motion (regeneration credited), all actuators,
    fine grid. The breakdown is at the windings' reference resistance; with ``hot_windings`` (the study's duty
    model) the cumulative energy is the study's, at the hot windings' R_s(T), and the right title says so.
    """
    fig = new_figure((13.0, 4.6))
    left, right = fig.subplots(1, 2, width_ratios=(1.45, 1.0))
    names = ("initial", "optimal")
    bars = {}
    for n in names:
        parts = checks[n].summary.energy_breakdown_J.as_tuple()
        bars[n] = (*parts[:-1], drive_train_energy(emlas, checks[n], time), parts[-1])
    energy_bars(left, bars)
    cold = ", windings at their reference resistance" if hot_windings else ""
    left.set_title(f"Where the energy goes\n(all actuators{cold})", fontsize=10)
    cumulative_energy(right, time, {n: checks[n].evaluation.power for n in names})
    hot = "\n(hot windings: the study's duty model)" if hot_windings else ""
    right.set_title(f"Cumulative net electrical energy{hot}", fontsize=10)
    save_png(fig, path)


def sensitivity_figure(sensitivity: Sensitivity, path: Path) -> None:
    """The active constraints' multipliers in physical units (result.json -> sensitivity)."""
    fig = new_figure((10.0, 5.0))
    sensitivity_bars(fig.add_subplot(), sensitivity)
    save_png(fig, path)


def chain_variables(lengths: DesignValues) -> list[tuple[str, list[int], list[str]]]:
    """Per chain: its name, the indices of its decision variables in Xi and their labels (the design's names)."""
    out: dict[str, tuple[list[int], list[str]]] = {}
    for k, name in enumerate(lengths.names):
        chain, variable = name.split(".", 1)
        out.setdefault(chain, ([], []))
        out[chain][0].append(k)
        out[chain][1].append(variable)
    return [(c, idx, labels) for c, (idx, labels) in out.items()]


def write_figures(
    out: Path,
    crane: Crane | None,
    emlas: EmlaSet,
    result: Result,
    arrays: dict[str, np.ndarray],
    checks: dict[str, DesignCheck],
) -> list[Path]:
    """Write every figure into ``out``; return their paths."""
    designs = {"initial": result.initial.lengths, "optimal": result.optimal.lengths}
    history = result.history
    chains = chain_variables(result.optimal.lengths)
    paths = {
        "objective": out / "objective.png",
        **{c: out / f"decision_variables_{c}.png" for c, _, _ in chains},
        "structure": out / "structure_initial_vs_optimal.png",
        "spiral": out / "crane_spiral.png",
        "actuators": out / "actuators_force_velocity_power.png",
        "maps": out / "efficiency_maps.png",
        "energy": out / "energy_breakdown.png",
    }
    objective_figure(history, paths["objective"], result.energy.objective if result.energy is not None else "costf2")
    low, up = np.asarray(result.settings.xi_low), np.asarray(result.settings.xi_up)
    for c, indices, labels in chains:
        decision_figure(history, indices, labels, c, paths[c], low, up)
    if crane is None:  # a machine file's study: the crane's structure and spiral drawings do not apply
        del paths["structure"], paths["spiral"]
    else:
        loads = result.structure
        most, over, prefix, of_task = None, "the motion", "", ""
        if loads is not None:
            pin = loads.optimal.most_loaded_pin
            most = (pin, loads.optimal.pins[pin].peak_N)
            envelope = loads.optimal.envelope
            if envelope is not None:  # a duty mix: drawn in the motion of the task that sets the peak
                task = envelope.pin_peak_task[pin]
                prefix, of_task = f"task{envelope.tasks.index(task)}_", f" of task {task}"
                over = f"the tasks (task {task})"
        drawn = arrays[f"{prefix}optimal_position"]
        mid = len(drawn) // 2
        label = f"t = {arrays[f'{prefix}time'][mid]:.2f} s of the optimal motion{of_task}"
        structure_figure(
            crane, {k: crane_lengths(v) for k, v in designs.items()}, drawn[mid], paths["structure"], label, most, over
        )
        spiral_figure(
            crane,
            crane_lengths(designs["optimal"]),
            arrays["optimal_position"],
            arrays["reference_tcp"],
            arrays["optimal_tcp"],
            paths["spiral"],
            arrays["time"],
        )
    actuator_figure(arrays["time"], checks, paths["actuators"])
    efficiency_figure(emlas, checks, paths["maps"])
    duty = result.energy.optimal.duty if result.energy is not None else None
    hot = duty is not None and duty.hot_winding_extra_J != 0.0
    energy_figure(arrays["time"], checks, paths["energy"], emlas, hot_windings=hot)
    if result.sensitivity is not None:
        paths["sensitivity"] = out / "sensitivity.png"
        sensitivity_figure(result.sensitivity, paths["sensitivity"])
    structure = result.structure
    # the frequencies need every drive's screw and stiffness data: drawn where the result has them
    if crane is not None and structure is not None and structure.optimal.lowest_frequency_working_range_Hz is not None:
        from hiab_sim.structure.report import natural_frequency_figure

        paths["frequency"] = natural_frequency_figure(
            crane, emlas, result, arrays, out / "structure_natural_frequency.png"
        )
    hydraulic = hydraulic_figure(out / "energy_emla_vs_hydraulic.png", result)
    return list(paths.values()) + hydraulic

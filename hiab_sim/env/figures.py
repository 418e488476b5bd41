"""Figures of the closed-loop validation (Agg backend, PNG written atomically).

* ``closed_loop_tcp_error.png``: TCP error to the study's reference over time, per design;
* ``closed_loop_drives.png``: q-currents with the current limit and |v_dq| with the voltage limit;
* ``closed_loop_power.png``: closed-loop vs predicted electrical power on the DC bus;
* ``closed_loop_energy.png``: cumulative net electrical energy, closed loop vs predicted.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.env.rollout import ClosedLoopRun
from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.style import COLOURS

#: Resolution of the closed-loop figures [dots per inch].
DPI = 110
DRIVE_COLOURS = ("tab:green", "tab:purple", "tab:orange")


def _label(run: ClosedLoopRun) -> str:
    extra = f", end mass +{100 * run.payload_error:g} %" if run.payload_error else ""
    task = "" if run.task is None else f", task {run.task}"
    return f"{run.design}{task}{extra}"


def _cumulative(power: np.ndarray, time: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(time))])


def _colour(run: ClosedLoopRun) -> str:
    """The design's colour of the one visual language (hiab_sim.style); black for another design."""
    return COLOURS.get(run.design, COLOURS["reference"])


def _style(run: ClosedLoopRun) -> dict[str, Any]:
    return {
        "color": _colour(run),
        "linestyle": "-" if run.payload_error == 0 else "-.",
    }


def write_figures(
    folder: Path, runs: list[ClosedLoopRun], nominal: list[ClosedLoopRun] | None = None, suffix: str = ""
) -> list[Path]:
    """Write the four figures of the module docstring, ``suffix`` before ``.png``; return their paths.

    The drive figure shows ``runs``; the others also the ``nominal`` runs of a payload-error study.
    A duty mix's tasks each get their own (``suffix`` ``_task<k>``).
    """
    paths = []
    every = [*(nominal or []), *runs]
    fig = new_figure((8.0, 3.6))
    ax = fig.add_subplot()
    for run in every:
        ax.plot(run.time, 1000.0 * run.tcp_error, label=f"{_label(run)}: to the reference", **_style(run))
    for run in runs:
        colour = _colour(run)
        ax.plot(
            run.time,
            1000.0 * run.plan_error,
            color=colour,
            linestyle=":",
            linewidth=0.9,
            label=f"{_label(run)}: to the plan",
        )
    ax.set(xlabel="time [s]", ylabel="TCP error [mm]", title="Closed-loop TCP tracking error")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    paths.append(save_png(fig, folder / f"closed_loop_tcp_error{suffix}.png", DPI))

    fig = new_figure((4.2 * len(runs), 5.6))
    axes = fig.subplots(2, len(runs), squeeze=False, sharex=True)
    for column, run in enumerate(runs):
        top, bottom = axes[0, column], axes[1, column]
        for i, name in enumerate(run.actuator_names):
            colour = DRIVE_COLOURS[i % len(DRIVE_COLOURS)]
            top.plot(run.time, run.current_dq[:, i, 1], color=colour, label=f"{name} i_q")
            top.plot(run.time, run.current_dq[:, i, 0], color=colour, linestyle=":", linewidth=0.8)
            magnitude = np.hypot(run.voltage_dq[:, i, 0], run.voltage_dq[:, i, 1])
            bottom.plot(run.time, magnitude, color=colour, label=f"{name} |v_dq|")
        for sign in (1.0, -1.0):
            top.axhline(sign * run.current_limit[0], color="k", linestyle="--", linewidth=0.8)
        bottom.axhline(run.voltage_limit[0], color="k", linestyle="--", linewidth=0.8, label="inverter limit")
        top.set(ylabel="current [A] (dotted: i_d)", title=_label(run))
        bottom.set(xlabel="time [s]", ylabel="voltage |v_dq| [V]")
        for ax in (top, bottom):
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
    paths.append(save_png(fig, folder / f"closed_loop_drives{suffix}.png", DPI))

    paths.append(
        _closed_vs_predicted(
            folder / f"closed_loop_power{suffix}.png",
            every,
            runs,
            lambda run: run.electrical_power.sum(axis=1) / 1e3,
            lambda run: run.predicted_power.sum(axis=1) / 1e3,
            ylabel="DC bus power [kW]",
            title="Electrical power, closed loop vs predicted",
        )
    )
    paths.append(
        _closed_vs_predicted(
            folder / f"closed_loop_energy{suffix}.png",
            every,
            runs,
            lambda run: run.cumulative_energy.sum(axis=1) / 1e3,
            lambda run: _cumulative(run.predicted_power.sum(axis=1), run.plan_time) / 1e3,
            ylabel="net electrical energy [kJ]",
            title="Cumulative net electrical energy",
        )
    )
    return paths


def _closed_vs_predicted(
    path: Path,
    every: list[ClosedLoopRun],
    runs: list[ClosedLoopRun],
    closed: Callable[[ClosedLoopRun], np.ndarray],
    predicted: Callable[[ClosedLoopRun], np.ndarray],
    *,
    ylabel: str,
    title: str,
) -> Path:
    """One figure: ``closed`` of every run against time, dashed ``predicted`` of each design on its plan's time."""
    fig = new_figure((8.0, 3.6))
    ax = fig.add_subplot()
    for run in every:
        ax.plot(run.time, closed(run), label=f"{_label(run)}: closed loop", **_style(run))
    for run in runs:
        ax.plot(run.plan_time, predicted(run), color=_colour(run), linestyle="--", label=f"{run.design}: predicted")
    ax.set(xlabel="time [s]", ylabel=ylabel, title=title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save_png(fig, path, DPI)

"""What a report shows of the structure: a table of pins, screws and frequencies, and the frequency figure.

:func:`structure_table` prints a result's ``structure`` section (:mod:`hiab_sim.structure.summary`)
as a Markdown table, initial vs optimal: each pin's peak load and fatigue range, each screw's
buckling utilisation, the lowest natural frequency and, given the velocity loop's bandwidth, its
margin (:func:`hiab_sim.structure.natural_frequency.bandwidth_margin`); a duty mix's envelope
names in brackets the task that sets each value, and :func:`task_structure_table` lists every
task's own values beside the envelope.
:func:`natural_frequency_figure` draws the lowest natural frequency over the working range (the
chains' joints, the direct joint at the trajectory's mean) for both designs with their trajectories
and names the most loaded pin.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane
from hiab_sim.emla.config import EmlaSet
from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.results.schema import Result
from hiab_sim.structure.natural_frequency import bandwidth_margin, natural_frequencies
from hiab_sim.structure.summary import DesignStructure, StructureSummary

DESIGNS = ("initial", "optimal")


def _cell(value: float | None, scale: float = 1.0, digits: int = 1) -> str:
    return "-" if value is None else f"{value / scale:.{digits}f}"


def _task(design: DesignStructure, kind: str, key: str | None = None) -> str:
    """`` (task)``: the task of a mix's envelope that sets a value (``kind``: pin, screw, path, grid); else empty."""
    e = design.envelope
    if e is None:
        return ""
    task = {
        "pin": e.pin_peak_task.get(key or ""),
        "screw": e.buckling_task.get(key or ""),
        "path": e.lowest_frequency_trajectory_task,
        "grid": e.lowest_frequency_working_range_task,
    }[kind]
    return "" if task is None else f" ({task})"


def structure_table(summary: StructureSummary, velocity_bandwidth_Hz: float | None = None) -> str:
    """Markdown table of the ``structure`` section, initial vs optimal (kN, -, Hz); a mix's tasks in brackets."""
    designs = [summary.initial, summary.optimal]
    lines = [
        "| quantity | initial | optimal |",
        "|---|---:|---:|",
    ]
    for name in summary.initial.pins:
        cells = [
            f"{_cell(d.pins[name].peak_N, 1e3)} / {_cell(d.pins[name].vector_range_N, 1e3)}{_task(d, 'pin', name)}"
            for d in designs
        ]
        lines.append(f"| pin {name}: peak / range [kN] | {cells[0]} | {cells[1]} |")
    for name in summary.initial.buckling:
        n = summary.initial.buckling_safety_factor
        cells = [_cell(d.buckling[name].max_utilisation, digits=3) + _task(d, "screw", name) for d in designs]
        lines.append(f"| {name} screw: max n f / P_cr (n = {n:g}, <= 1 holds) | {cells[0]} | {cells[1]} |")
    envelopes = [d.envelope for d in designs]
    if envelopes[0] is not None and envelopes[1] is not None and envelopes[0].smallest_buckling_margin is not None:
        cells = [
            f"{e.smallest_buckling_margin:.3f} ({e.smallest_buckling_margin_screw}, {e.smallest_buckling_margin_task})"
            for e in envelopes
            if e is not None and e.smallest_buckling_margin is not None
        ]
        lines.append(f"| smallest buckling margin 1 - n f / P_cr over the tasks | {cells[0]} | {cells[1]} |")
    for key, label, kind in (
        ("lowest_frequency_trajectory_Hz", "lowest natural frequency on the trajectory [Hz]", "path"),
        ("lowest_frequency_working_range_Hz", "lowest natural frequency over the working range [Hz]", "grid"),
    ):
        cells = [_cell(getattr(d, key), digits=2) + _task(d, kind) for d in designs]
        lines.append(f"| {label} | {cells[0]} | {cells[1]} |")
    if velocity_bandwidth_Hz is not None:
        margins = [
            "-"
            if d.lowest_frequency_working_range_Hz is None
            else f"{bandwidth_margin(velocity_bandwidth_Hz, d.lowest_frequency_working_range_Hz):.2f}"
            for d in designs
        ]
        lines.append(
            f"| velocity loop {velocity_bandwidth_Hz:g} Hz vs a third of the lowest frequency: margin (>= 0 holds) "
            f"| {margins[0]} | {margins[1]} |"
        )
    most = [d.most_loaded_pin + _task(d, "pin", d.most_loaded_pin) for d in designs]
    lines.append(f"| most loaded pin | {most[0]} | {most[1]} |")
    return "\n".join(lines)


def task_structure_table(tasks: Sequence[tuple[str, StructureSummary]], envelope: StructureSummary) -> str:
    """Markdown table of a duty mix: each task's own values and the envelope, cells ``initial / optimal``."""
    names = [name for name, _ in tasks]
    sections = [s for _, s in tasks] + [envelope]
    lines = [
        "| quantity (initial / optimal) | " + " | ".join(names) + " | envelope |",
        "|---|" + "---:|" * (len(names) + 1),
    ]

    def row(label: str, value: Callable[[DesignStructure], float | None], scale: float = 1.0, digits: int = 1) -> None:
        cells = [
            f"{_cell(value(d.initial), scale, digits)} / {_cell(value(d.optimal), scale, digits)}" for d in sections
        ]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")

    def peak(pin: str) -> Callable[[DesignStructure], float | None]:
        return lambda d: d.pins[pin].peak_N

    def utilisation(screw: str) -> Callable[[DesignStructure], float | None]:
        return lambda d: d.buckling[screw].max_utilisation

    for pin in envelope.initial.pins:
        row(f"pin {pin}: peak [kN]", peak(pin), 1e3)
    for screw in envelope.initial.buckling:
        row(f"{screw} screw: max n f / P_cr", utilisation(screw), digits=3)
    row("lowest natural frequency on the trajectory [Hz]", lambda d: d.lowest_frequency_trajectory_Hz, digits=2)
    row("lowest natural frequency over the working range [Hz]", lambda d: d.lowest_frequency_working_range_Hz, digits=2)
    return "\n".join(lines)


def frequency_grid(
    crane: Crane, emlas: EmlaSet, lengths: object, direct_joint: float, count: int = 41
) -> tuple[Array, Array, Array]:
    """Lowest frequency [Hz] on a count x count grid of the chains' working ranges, direct joint fixed."""
    from hiab_sim.crane.description import LinkLengths

    assert isinstance(lengths, LinkLengths)
    (a0, a1), (b0, b1) = (chain.joint_range for chain in crane.chains[:2])
    first, second = np.meshgrid(np.linspace(a0, a1, count), np.linspace(b0, b1, count), indexing="xy")
    poses = np.stack([first.ravel(), second.ravel(), np.full(first.size, direct_joint)], axis=1)
    lowest = natural_frequencies(crane, emlas, lengths, poses).lowest_Hz.reshape(first.shape)
    return first, second, lowest


def _trajectories(result: Result, arrays: Mapping[str, Array], design: str) -> list[tuple[str, Array]]:
    """(label, joint positions (T, 3)) of a design: its one trajectory, or a duty mix's every task's."""
    if result.tasks is None:
        return [("trajectory", np.asarray(arrays[f"{design}_position"]))]
    return [(f"task {t.name}", np.asarray(arrays[f"task{k}_{design}_position"])) for k, t in enumerate(result.tasks)]


def natural_frequency_figure(
    crane: Crane, emlas: EmlaSet, result: Result, arrays: Mapping[str, Array], path: Path
) -> Path:
    """PNG of the lowest natural frequency over the working range, initial and optimal design (module docstring).

    ``arrays``: the result folder's ``trajectory.npz`` (``<design>_position``, (T, 3); a duty mix's
    ``task<k>_<design>_position``, every task's trajectory drawn and the direct joint at their mean).
    """
    fig = new_figure((10.0, 4.2))
    axes = fig.subplots(1, 2, sharex=True, sharey=True)
    grids = {}
    for design in DESIGNS:
        paths = _trajectories(result, arrays, design)
        direct = float(np.mean(np.concatenate([position[:, 2] for _, position in paths])))
        lengths = getattr(result, design).lengths
        grids[design] = (paths, frequency_grid(crane, emlas, lengths, direct))
    low = min(float(g[1][2].min()) for g in grids.values())
    high = max(float(g[1][2].max()) for g in grids.values())
    levels = np.linspace(low, high, 15)
    names = [chain.name for chain in crane.chains[:2]]
    styles = ("-", "--", ":", "-.")
    for ax, design in zip(axes, DESIGNS, strict=True):
        paths, (first, second, lowest) = grids[design]
        filled = ax.contourf(np.degrees(first), np.degrees(second), lowest, levels=levels, cmap="viridis")
        for j, (label, position) in enumerate(paths):
            ax.plot(
                np.degrees(position[:, 0]),
                np.degrees(position[:, 1]),
                color="white",
                ls=styles[j % len(styles)],
                lw=1.5,
                label=label,
            )
        k = np.unravel_index(int(np.argmin(lowest)), lowest.shape)
        ax.plot(np.degrees(first[k]), np.degrees(second[k]), "rv", label=f"min {lowest[k]:.2f} Hz")
        summary = result.structure
        title = design
        if summary is not None:
            d = getattr(summary, design)
            title += f": most loaded pin {d.most_loaded_pin} ({d.pins[d.most_loaded_pin].peak_N / 1e3:.1f} kN"
            title += ")" if d.envelope is None else f", task {d.envelope.pin_peak_task[d.most_loaded_pin]})"
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(f"{names[0]} joint [deg]")
        ax.legend(loc="upper right", fontsize=8)
    axes[0].set_ylabel(f"{names[1]} joint [deg]")
    fig.colorbar(filled, ax=list(axes), label="lowest natural frequency [Hz]")
    return save_png(fig, path)

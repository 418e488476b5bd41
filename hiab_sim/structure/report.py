"""What a report shows of the structure: a table of pins, screws and frequencies, and the frequency figure.

:func:`structure_table` prints a result's ``structure`` section (:mod:`hiab_sim.structure.summary`)
as a Markdown table, initial vs optimal: each pin's peak load and fatigue range, each screw's
buckling utilisation, the lowest natural frequency and, given the velocity loop's bandwidth, its
margin (:func:`hiab_sim.structure.natural_frequency.bandwidth_margin`).
:func:`natural_frequency_figure` draws the lowest natural frequency over the working range (the
chains' joints, the direct joint at the trajectory's mean) for both designs with their trajectories
and names the most loaded pin.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiab_sim.crane.description import Crane
from hiab_sim.emla.config import EmlaSet
from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.results.schema import Result
from hiab_sim.structure.natural_frequency import bandwidth_margin, natural_frequencies
from hiab_sim.structure.summary import StructureSummary

Array = NDArray[np.float64]
DESIGNS = ("initial", "optimal")


def _cell(value: float | None, scale: float = 1.0, digits: int = 1) -> str:
    return "-" if value is None else f"{value / scale:.{digits}f}"


def structure_table(summary: StructureSummary, velocity_bandwidth_Hz: float | None = None) -> str:
    """Markdown table of the ``structure`` section, initial vs optimal (kN, -, Hz)."""
    designs = [summary.initial, summary.optimal]
    lines = [
        "| quantity | initial | optimal |",
        "|---|---:|---:|",
    ]
    for name in summary.initial.pins:
        peaks = [_cell(d.pins[name].peak_N, 1e3) for d in designs]
        ranges = [_cell(d.pins[name].vector_range_N, 1e3) for d in designs]
        lines.append(f"| pin {name}: peak / range [kN] | {peaks[0]} / {ranges[0]} | {peaks[1]} / {ranges[1]} |")
    for name in summary.initial.buckling:
        n = summary.initial.buckling_safety_factor
        cells = [_cell(d.buckling[name].max_utilisation, digits=3) for d in designs]
        lines.append(f"| {name} screw: max n f / P_cr (n = {n:g}, <= 1 holds) | {cells[0]} | {cells[1]} |")
    for key, label in (
        ("lowest_frequency_trajectory_Hz", "lowest natural frequency on the trajectory [Hz]"),
        ("lowest_frequency_working_range_Hz", "lowest natural frequency over the working range [Hz]"),
    ):
        cells = [_cell(getattr(d, key), digits=2) for d in designs]
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
    most = [d.most_loaded_pin for d in designs]
    lines.append(f"| most loaded pin | {most[0]} | {most[1]} |")
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


def natural_frequency_figure(
    crane: Crane, emlas: EmlaSet, result: Result, arrays: Mapping[str, Array], path: Path
) -> Path:
    """PNG of the lowest natural frequency over the working range, initial and optimal design (module docstring).

    ``arrays``: the result folder's ``trajectory.npz`` (``<design>_position``, (T, 3)).
    """
    fig = new_figure((10.0, 4.2))
    axes = fig.subplots(1, 2, sharex=True, sharey=True)
    grids = {}
    for design in DESIGNS:
        position = np.asarray(arrays[f"{design}_position"])
        lengths = getattr(result, design).lengths
        grids[design] = (position, frequency_grid(crane, emlas, lengths, float(np.mean(position[:, 2]))))
    low = min(float(g[1][2].min()) for g in grids.values())
    high = max(float(g[1][2].max()) for g in grids.values())
    levels = np.linspace(low, high, 15)
    names = [chain.name for chain in crane.chains[:2]]
    for ax, design in zip(axes, DESIGNS, strict=True):
        position, (first, second, lowest) = grids[design]
        filled = ax.contourf(np.degrees(first), np.degrees(second), lowest, levels=levels, cmap="viridis")
        ax.plot(np.degrees(position[:, 0]), np.degrees(position[:, 1]), color="white", lw=1.5, label="trajectory")
        k = np.unravel_index(int(np.argmin(lowest)), lowest.shape)
        ax.plot(np.degrees(first[k]), np.degrees(second[k]), "rv", label=f"min {lowest[k]:.2f} Hz")
        summary = result.structure
        title = design
        if summary is not None:
            d = getattr(summary, design)
            title += f": most loaded pin {d.most_loaded_pin} ({d.pins[d.most_loaded_pin].peak_N / 1e3:.1f} kN)"
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(f"{names[0]} joint [deg]")
        ax.legend(loc="upper right", fontsize=8)
    axes[0].set_ylabel(f"{names[1]} joint [deg]")
    fig.colorbar(filled, ax=list(axes), label="lowest natural frequency [Hz]")
    return save_png(fig, path)

"""Figures that read at a glance: one colour per design (:mod:`hiab_sim.style`) everywhere.

* :func:`structure_overlay`: both designs on one axes in the pose the title names, each base
  pivot's shift dimensioned (arrow and millimetres), the lengths in the legend, not over the crane;
* :func:`decision_panels`: L, Lc0, Lc of one chain per SQP iteration, one panel each, with the region
  outside the bounds shaded;
* :func:`energy_bars`, :func:`cumulative_energy`: the energy breakdown with the value on every
  bar, and the cumulative net electrical energy over the motion;
* :func:`sensitivity_bars`: the active constraints' multipliers (cost decrease per unit of
  relaxation, in % of the optimal cost), from ``result.json`` -> ``sensitivity``.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.axes import Axes

from hiab_sim.arrays import Array
from hiab_sim.crane.description import CHAIN_NAMES, Crane, LinkLengths
from hiab_sim.crane.kinematics import forward_kinematics
from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.results.analysis_sections import Sensitivity
from hiab_sim.results.schema import HistoryRow
from hiab_sim.study.report.summary import limit_in_words
from hiab_sim.style import colour

#: The bars of :func:`energy_bars`: the breakdown's parts, the drive train's (:func:`drive_train_energy`), the total.
ENERGY_LABELS = (
    "mechanical\nf v",
    "copper",
    "rotor\nfriction",
    "screw\nviscous",
    "inertial",
    "drive train:\nscrew, gear,\ninverter, brake",
    "net\nelectrical",
)


def draw_crane(ax: Axes, crane: Crane, lengths: LinkLengths, joints: Array, colour: str, alpha: float = 1.0) -> None:
    """Draw the crane's links in its vertical plane of motion at one joint pose (theta1, theta2, xt2)."""
    f = forward_kinematics(crane, lengths, joints[0:1], joints[1:2], joints[2:3])

    def seg(a: Array, b: Array, **kw: Any) -> None:
        ax.plot([a[0, 0], b[0, 0]], [a[0, 1], b[0, 1]], color=colour, alpha=alpha, **kw)

    origin = np.zeros((1, 3))
    # the booms in the crane's order (each chain's boom), then the telescope's cylinder and the TCP
    booms = [f"{chain.name}_boom" for chain in crane.chains] + [f"{ACTUATOR_NAMES[-1]}_cylinder", "tcp"]
    seg(origin, f.position[booms[0]], linewidth=4)
    for chain in crane.chains:
        xi = getattr(lengths, chain.name)
        base = f.position[f"{chain.name}_cylinder"]
        rod_end = f.point(f"{chain.name}_rod", [xi.Lc, 0.0, 0.0])
        seg(base, f.point(f"{chain.name}_cylinder", [xi.x0 * 0.95, 0.0, 0.0]), linewidth=5, solid_capstyle="butt")
        seg(base, rod_end, linewidth=2, linestyle="-")
        seg(f.position[f"{chain.name}_boom"], rod_end, linewidth=3)
        ax.plot(*base[0, :2], "o", color=colour, alpha=alpha, markersize=5)
    for k, (a, b) in enumerate(itertools.pairwise(booms)):
        seg(f.position[a], f.position[b], linewidth=3 if k == len(booms) - 2 else 4)
    ax.plot(*f.position["tcp"][0, :2], "s", color=colour, alpha=alpha, markersize=5)


def _lengths_label(name: str, lengths: LinkLengths) -> str:
    return f"{name}: " + ",  ".join(
        f"{c} L {getattr(lengths, c).L:.3f} Lc0 {getattr(lengths, c).Lc0:.3f} Lc {getattr(lengths, c).Lc:.3f}"
        for c in CHAIN_NAMES
    )


def structure_overlay(
    ax: Axes,
    crane: Crane,
    designs: dict[str, LinkLengths],
    pose: Array,
    pose_label: str,
    most_loaded: tuple[str, float] | None = None,
    over: str = "the motion",
) -> None:
    """Both designs on one axes at ``pose``, each base pivot's shift as an arrow labelled in mm.

    ``most_loaded``: (pin name ``<chain>.<pin>``, its peak force [N] over ``over``) of the last design,
    ringed and labelled at its place in the pose (a duty mix: over its tasks, naming the task).
    """
    pivots: dict[str, dict[str, Array]] = {}
    for name, lengths in designs.items():
        draw_crane(ax, crane, lengths, pose, colour(name), alpha=0.9)
        ax.plot([], [], color=colour(name), linewidth=4, label=_lengths_label(name, lengths) + " m")
        f = forward_kinematics(crane, lengths, pose[0:1], pose[1:2], pose[2:3])
        pivots[name] = {c.name: f.position[f"{c.name}_cylinder"][0, :2] for c in crane.chains}
    names = list(designs)
    if len(names) >= 2:
        for k, chain in enumerate(crane.chains):
            a, b = pivots[names[0]][chain.name], pivots[names[-1]][chain.name]
            shift = float(np.hypot(*(b - a)))
            ax.annotate(
                "",
                xy=(b[0], b[1]),
                xytext=(a[0], a[1]),
                arrowprops={"arrowstyle": "->", "color": "0.2", "linewidth": 1.2},
            )
            ax.annotate(
                f"{chain.name} base pivot\nmoves {shift * 1e3:.0f} mm",
                xy=(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])),
                xytext=(40, 60) if k == 0 else (60, -60),  # right of the pivot: inside the axes
                textcoords="offset points",
                fontsize=8,
                arrowprops={"arrowstyle": "-", "color": "0.5", "linewidth": 0.6},
            )
    if most_loaded is not None:
        _mark_pin(ax, crane, designs[names[-1]], pose, *most_loaded, over=over)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("horizontal distance from the column [m]")
    ax.set_ylabel("height above the column base [m]")
    ax.set_title(f"Initial and optimal structure at {pose_label}")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), fontsize=8, frameon=False)


def _mark_pin(
    ax: Axes, crane: Crane, lengths: LinkLengths, pose: Array, pin: str, peak_N: float, over: str = "the motion"
) -> None:
    """Ring the pin ``<chain>.<kind>`` at ``pose`` and label it with its peak force over ``over`` in kN."""
    from hiab_sim.structure.pin_loads import chain_links

    chain, kind = pin.split(".", 1)
    boom, cylinder, rod = chain_links(chain)
    link = {"base_pivot": cylinder, "boom_hinge": boom, "rod_end": rod}[kind]
    f = forward_kinematics(crane, lengths, pose[0:1], pose[1:2], pose[2:3])
    x, y = f.position[link][0, :2]
    ax.plot([x], [y], "o", markersize=14, markerfacecolor="none", markeredgecolor="tab:red", markeredgewidth=2)
    ax.annotate(
        f"most loaded pin: {chain} {kind.replace('_', ' ')}\n{peak_N / 1e3:.1f} kN peak over {over}",
        xy=(x, y),
        xytext=(40, 20),
        textcoords="offset points",
        fontsize=8,
        color="tab:red",
        arrowprops={"arrowstyle": "-", "color": "tab:red", "linewidth": 0.8},
    )


def decision_panels(
    axes: Any, history: tuple[HistoryRow, ...], indices: Sequence[int], labels: Sequence[str], low: Array, up: Array
) -> None:
    """One chain's decision variables (Xi entries ``indices``) per iteration, one panel each, out of bounds grey."""
    it = [h.iteration for h in history]
    for ax, k, label in zip(axes, indices, labels, strict=True):
        values = [h.xi[k] for h in history]
        span = max(up[k] - low[k], 1e-3)
        lo_view, hi_view = low[k] - 0.08 * span, up[k] + 0.08 * span
        ax.axhspan(lo_view, low[k], color="0.85", zorder=0)
        ax.axhspan(up[k], hi_view, color="0.85", zorder=0)
        ax.axhline(low[k], color="0.4", linewidth=0.8)
        ax.axhline(up[k], color="0.4", linewidth=0.8)
        ax.plot(it, values, "o-", markersize=3, color=colour("optimal"))
        ax.plot(it[:1], values[:1], "o", color=colour("initial"), markersize=6, label="initial")
        ax.set_ylim(lo_view, hi_view)
        ax.set_ylabel(f"{label} [m]")
        ax.text(
            1.0, 1.0, f"bounds [{low[k]:g}, {up[k]:g}] m", transform=ax.transAxes, ha="right", va="bottom", fontsize=7
        )
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("SQP iteration")


def energy_bars(ax: Axes, breakdown: dict[str, tuple[float, ...]]) -> None:
    """Energy breakdown per design [kJ] with the value on every bar, one value per :data:`ENERGY_LABELS`."""
    x = np.arange(len(ENERGY_LABELS))
    width = 0.8 / len(breakdown)
    for k, (name, parts) in enumerate(breakdown.items()):
        values = [v / 1e3 for v in parts]
        bars = ax.bar(x + (k - 0.5 * (len(breakdown) - 1)) * width, values, width, color=colour(name), label=name)
        ax.bar_label(bars, labels=[f"{v:.3f}" for v in values], fontsize=7, padding=2, rotation=90)
    ax.set_xticks(x, ENERGY_LABELS)
    ax.set_ylabel("energy over the motion [kJ]")
    ax.axhline(0.0, color="0.3", linewidth=0.6)
    ax.margins(y=0.25)
    ax.legend()


def cumulative_energy(ax: Axes, time: Array, power: dict[str, Array]) -> None:
    """Cumulative net electrical energy sum_i int P_i dt [kJ] per design (trapezoid rule)."""
    for name, p in power.items():
        total = p.sum(axis=1)
        energy = np.concatenate([[0.0], np.cumsum(0.5 * (total[1:] + total[:-1]) * np.diff(time))])
        ax.plot(time, energy / 1e3, color=colour(name), label=f"{name}: {energy[-1] / 1e3:.3f} kJ")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("cumulative net electrical energy [kJ]")
    ax.grid(alpha=0.3)
    ax.legend()


def sensitivity_bars(ax: Axes, sensitivity: Sensitivity, count: int = 12) -> None:
    """The largest multipliers as % of the optimal cost per unit of relaxation, labelled with the unit."""
    rows = sensitivity.multipliers[:count][::-1]
    y = np.arange(len(rows))
    values = [m.percent_per_unit for m in rows]
    bars = ax.barh(y, values, color="0.45")  # one neutral colour: the bars are limits, not designs
    ax.bar_label(
        bars, labels=[f"{v:.3g} % per {m.unit}" for v, m in zip(values, rows, strict=True)], fontsize=8, padding=2
    )
    ax.set_yticks(y, [limit_in_words(m.constraint) for m in rows], fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("objective saved if the limit were relaxed by one unit [% of the optimal objective]")
    fit = "exact" if sensitivity.kkt_residual < 1e-6 else f"fit residual {sensitivity.kkt_residual:.0e}"
    ax.set_title(f"Which limits hold the design back, and by how much\n(optimality-condition multipliers, {fit})")
    ax.margins(x=0.35)
    ax.grid(alpha=0.3, axis="x")

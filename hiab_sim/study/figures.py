"""Figures of an optimisation result (Agg backend, written atomically as PNG).

Seed figures: objective per iteration (Fig. ``Objective_function``), decision variables per
iteration (Figs. ``Decision_variables_1/2``), initial vs optimal structure (Fig.
``Initial_Structure_Modified``), the crane with the spiral (Fig. ``hiab``); plus actuator force,
velocity and electrical power over time, operating points on the efficiency maps, and the energy
breakdown, initial vs optimal.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from hiab_sim.atomic_io import write_atomic
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.kinematics import forward_kinematics
from hiab_sim.emla import EmlaSet
from hiab_sim.study.energy_figure import hydraulic_figure
from hiab_sim.study.problem import ACTUATORS
from hiab_sim.study.report import DesignCheck
from hiab_sim.study.result import ENERGY_PARTS, HistoryRow, Result

COLOURS = {"initial": "tab:blue", "optimal": "tab:red"}


def _figure(size: tuple[float, float]) -> Figure:
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Figure, path: Path) -> None:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=120)
    write_atomic(path, buffer.getvalue())


def draw_crane(
    ax: Axes, crane: Crane, lengths: LinkLengths, joints: np.ndarray, colour: str, alpha: float = 1.0
) -> None:
    """Draw the crane's links in the plane of {W} at one joint pose (theta1, theta2, xt2)."""
    f = forward_kinematics(crane, lengths, joints[0:1], joints[1:2], joints[2:3])

    def seg(a: np.ndarray, b: np.ndarray, **kw: Any) -> None:
        ax.plot([a[0, 0], b[0, 0]], [a[0, 1], b[0, 1]], color=colour, alpha=alpha, **kw)

    origin = np.zeros((1, 3))
    seg(origin, f.position["lift_boom"], linewidth=4)
    for chain in crane.chains:
        xi = getattr(lengths, chain.name)
        base = f.position[f"{chain.name}_cylinder"]
        rod_end = f.point(f"{chain.name}_rod", [xi.Lc, 0.0, 0.0])
        seg(base, f.point(f"{chain.name}_cylinder", [xi.x0 * 0.95, 0.0, 0.0]), linewidth=5, solid_capstyle="butt")
        seg(base, rod_end, linewidth=2, linestyle="-")
        seg(f.position[f"{chain.name}_boom"], rod_end, linewidth=3)
        ax.plot(*base[0, :2], "o", color=colour, alpha=alpha, markersize=5)
    seg(f.position["lift_boom"], f.position["tilt_boom"], linewidth=4)
    seg(f.position["tilt_boom"], f.position["telescope_cylinder"], linewidth=4)
    seg(f.position["telescope_cylinder"], f.position["tcp"], linewidth=3)
    ax.plot(*f.position["tcp"][0, :2], "s", color=colour, alpha=alpha, markersize=5)


def objective_figure(history: tuple[HistoryRow, ...], path: Path) -> None:
    """Scaled cost and max violation per SQP iteration (seed Fig. Objective_function)."""
    fig = _figure((6.5, 4.0))
    ax = fig.add_subplot()
    it = [h.iteration for h in history]
    ax.plot(it, [h.scaled_cost for h in history], "o-", color="tab:blue", markersize=3)
    ax.set_xlabel("SQP iteration")
    ax.set_ylabel("cost f / f(start)  (eq. costf2)")
    ax2 = ax.twinx()
    ax2.semilogy(it, [max(h.max_violation, 1e-16) for h in history], ".--", color="tab:gray", markersize=3)
    ax2.set_ylabel("max constraint violation (scaled)")
    ax.set_title("Objective per iteration")
    _save(fig, path)


def decision_figure(history: tuple[HistoryRow, ...], chain: int, name: str, path: Path) -> None:
    """L, Lc0, Lc of one chain per iteration (seed Figs. Decision_variables_1/2)."""
    fig = _figure((6.5, 4.0))
    ax = fig.add_subplot()
    it = [h.iteration for h in history]
    for j, label in enumerate(("L", "Lc0", "Lc")):
        ax.plot(it, [h.xi[3 * chain + j] for h in history], "o-", markersize=3, label=label)
    ax.set_xlabel("SQP iteration")
    ax.set_ylabel("length [m]")
    ax.set_title(f"Decision variables of the {name} chain")
    ax.legend()
    _save(fig, path)


def structure_figure(crane: Crane, designs: dict[str, LinkLengths], pose: np.ndarray, path: Path) -> None:
    """Initial and optimal structures side by side (seed Fig. Initial_Structure_Modified)."""
    fig = _figure((10.0, 4.6))
    axes = fig.subplots(1, 2, sharex=True, sharey=True)
    for ax, (name, lengths) in zip(axes, designs.items(), strict=True):
        draw_crane(ax, crane, lengths, pose, COLOURS[name])
        text = "\n".join(
            f"{c}: L={getattr(lengths, c).L:.3f}  Lc0={getattr(lengths, c).Lc0:.3f}  Lc={getattr(lengths, c).Lc:.3f} m"
            for c in ("lift", "tilt")
        )
        ax.text(0.02, 0.02, text, transform=ax.transAxes, fontsize=8, family="monospace")
        ax.set_title(f"{name} design")
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("y [m] (up)")
    _save(fig, path)


def spiral_figure(
    crane: Crane, lengths: LinkLengths, joints: np.ndarray, ref: np.ndarray, tcp: np.ndarray, path: Path
) -> None:
    """The crane at a few poses along the motion, with the reference spiral (seed Fig. hiab)."""
    fig = _figure((7.0, 5.0))
    ax = fig.add_subplot()
    for i, idx in enumerate(np.linspace(0, len(joints) - 1, 5).astype(int)):
        draw_crane(ax, crane, lengths, joints[idx], "0.3", alpha=0.25 + 0.15 * i)
    ax.plot(ref[:, 0], ref[:, 1], "-", color="tab:green", linewidth=2, label="reference spiral")
    ax.plot(tcp[:, 0], tcp[:, 1], "--", color="tab:red", linewidth=1, label="TCP (optimal design)")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m] (up)")
    ax.legend(loc="lower left", fontsize=8)
    ax.set_title("Crane following the spiral (vertical plane of {W})")
    _save(fig, path)


def actuator_figure(time: np.ndarray, checks: dict[str, DesignCheck], path: Path) -> None:
    """Force, velocity and electrical power per actuator over time, initial vs optimal."""
    fig = _figure((12.0, 8.0))
    axes = fig.subplots(3, 3, sharex=True)
    for name in ("initial", "optimal"):
        ev = checks[name].evaluation
        for i, act in enumerate(ACTUATORS):
            axes[0, i].plot(time, ev.actuators.force[:, i] / 1e3, color=COLOURS[name], label=name)
            axes[1, i].plot(time, ev.actuators.velocity[:, i], color=COLOURS[name])
            axes[2, i].plot(time, ev.power[:, i] / 1e3, color=COLOURS[name])
            axes[0, i].set_title(act)
    for i in range(3):
        axes[2, i].set_xlabel("time [s]")
    axes[0, 0].set_ylabel("force f_x [kN]")
    axes[1, 0].set_ylabel("velocity v_x [m/s]")
    axes[2, 0].set_ylabel("electrical power [kW]")
    axes[0, 0].legend()
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    _save(fig, path)


def efficiency_figure(emlas: EmlaSet, checks: dict[str, DesignCheck], path: Path) -> None:
    """Operating points (initial, optimal) over each actuator's efficiency map."""
    from hiab_sim.emla.maps import efficiency_map, plot_efficiency_map

    fig = _figure((19.0, 6.0))
    axes = fig.subplots(1, 3)
    for i, (ax, params) in enumerate(zip(axes, emlas, strict=True)):
        emap = efficiency_map(params, n_force=81, n_velocity=81)
        ini = checks["initial"].evaluation.actuators
        opt = checks["optimal"].evaluation.actuators
        plot_efficiency_map(emap, operating_points=(ini.force[:, i], ini.velocity[:, i]), ax=ax)
        ax.plot(opt.velocity[:, i], opt.force[:, i] / 1e3, ".", color="tab:red", markersize=3, label="optimal")
        ax.set_title(ax.get_title() + "\norange: initial design, red: optimal design", fontsize=9)
    _save(fig, path)


def energy_figure(checks: dict[str, DesignCheck], path: Path) -> None:
    """Energy breakdown (mechanical, copper, friction, inertial) initial vs optimal [kJ]."""
    fig = _figure((8.0, 4.2))
    ax = fig.add_subplot()
    x = np.arange(len(ENERGY_PARTS))
    for k, name in enumerate(("initial", "optimal")):
        b = checks[name].summary.energy_breakdown_J.as_tuple()
        ax.bar(x + (k - 0.5) * 0.38, [v / 1e3 for v in b], 0.38, color=COLOURS[name], label=name)
    ax.set_xticks(x, ["mechanical\nf v", "copper", "rotor\nfriction", "screw\nviscous", "inertial", "net\nelectrical"])
    ax.set_ylabel("energy over the motion [kJ]")
    ax.axhline(0.0, color="0.3", linewidth=0.6)
    ax.legend()
    ax.set_title("Energy breakdown (all actuators, fine grid)")
    _save(fig, path)


def write_figures(
    out: Path,
    crane: Crane,
    emlas: EmlaSet,
    result: Result,
    arrays: dict[str, np.ndarray],
    checks: dict[str, DesignCheck],
) -> list[Path]:
    """Write every figure into ``out``; return their paths."""
    designs = {"initial": result.initial.lengths, "optimal": result.optimal.lengths}
    history = result.history
    paths = {
        "objective": out / "objective.png",
        "lift": out / "decision_variables_lift.png",
        "tilt": out / "decision_variables_tilt.png",
        "structure": out / "structure_initial_vs_optimal.png",
        "spiral": out / "crane_spiral.png",
        "actuators": out / "actuators_force_velocity_power.png",
        "maps": out / "efficiency_maps.png",
        "energy": out / "energy_breakdown.png",
    }
    objective_figure(history, paths["objective"])
    decision_figure(history, 0, "lift", paths["lift"])
    decision_figure(history, 1, "tilt", paths["tilt"])
    joints = arrays["optimal_position"]
    structure_figure(crane, designs, joints[len(joints) // 2], paths["structure"])
    spiral_figure(crane, designs["optimal"], joints, arrays["reference_tcp"], arrays["optimal_tcp"], paths["spiral"])
    actuator_figure(arrays["time"], checks, paths["actuators"])
    efficiency_figure(emlas, checks, paths["maps"])
    energy_figure(checks, paths["energy"])
    hydraulic = hydraulic_figure(out / "energy_emla_vs_hydraulic.png", crane, result, checks["optimal"].evaluation)
    return list(paths.values()) + hydraulic

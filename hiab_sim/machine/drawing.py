"""Drawing of a machine: links, pivots, actuators and the TCP labelled, the reachable TCP workspace shaded.

The machine is drawn at the middle of every joint's working range, in the world plane (x forward,
y up, metres). The workspace is the set of TCP positions over every combination of the joints'
working ranges, sampled on a grid and shaded as the occupied cells of a 2D raster (so a crescent
stays a crescent); it is the workspace of the working ranges, which the assembly check holds
inside every chain's reachable range.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from hiab_sim.arrays import Array
from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.machine.description import Machine
from hiab_sim.machine.drawing_labels import LabelPlan, place_labels
from hiab_sim.machine.kinematics.assembly import joint_grid
from hiab_sim.machine.kinematics.forward import Frames, forward_kinematics, pin_positions

#: Grid samples per joint for the workspace, by number of joints (about 60 000 poses at most).
_PER_JOINT = {1: 400, 2: 250, 3: 40, 4: 16, 5: 9}
_RASTER = 160


def _xy(point: Array) -> tuple[float, float]:
    return (float(point[0]), float(point[1]))


def workspace_points(machine: Machine) -> Array:
    """TCP positions (N, 2) over the grid of the joints' working ranges [m]."""
    per_joint = _PER_JOINT.get(len(machine.joint_names), 5)
    return forward_kinematics(machine, joint_grid(machine, per_joint)).tcp_position[:, :2]


def _shade_workspace(ax: object, points: Array) -> None:
    low, high = points.min(axis=0), points.max(axis=0)
    span = np.maximum(high - low, 1e-6)
    idx = np.clip(((points - low) / span * (_RASTER - 1)).round().astype(int), 0, _RASTER - 1)
    grid = np.zeros((_RASTER, _RASTER), dtype=bool)
    grid[idx[:, 1], idx[:, 0]] = True
    filled = grid.copy()  # close one-cell gaps between samples
    filled[1:, :] |= grid[:-1, :]
    filled[:-1, :] |= grid[1:, :]
    filled[:, 1:] |= grid[:, :-1]
    filled[:, :-1] |= grid[:, 1:]
    image = np.zeros((_RASTER, _RASTER, 4))
    image[filled] = (0.35, 0.55, 0.85, 0.25)
    half = 0.5 * span / (_RASTER - 1)  # sample i sits at the centre of cell i: the cells reach half a cell beyond
    ax.imshow(  # type: ignore[attr-defined]
        image,
        origin="lower",
        extent=(low[0] - half[0], high[0] + half[0], low[1] - half[1], high[1] + half[1]),
        interpolation="nearest",
        zorder=0,
    )


def _link_points(machine: Machine, frames: Frames, link: str) -> list[Array]:
    """World points that outline a link: its origin, its children's joints, its pivots, the TCP."""
    points = [frames.position[link][:2]]
    points += [frames.position[c.name][:2] for c in machine.links if c.parent == link]
    for chain in machine.chains:
        points += [frames.point(p.link, p.position)[:2] for p in chain.pivots if p.link == link]
    if machine.tcp_link == link:
        points.append(frames.tcp_position[:2])
    return points


def draw_machine(machine: Machine) -> Figure:
    """The labelled drawing of the machine (see the module docstring)."""
    fig = new_figure((9.0, 7.0))
    ax = fig.add_subplot()
    middle = np.array([0.5 * sum(machine.joint_link(j).joint_range or (0.0, 0.0)) for j in machine.joint_names])
    frames = forward_kinematics(machine, middle)
    cloud = workspace_points(machine)
    _shade_workspace(ax, cloud)
    # Labels in order of importance: the first placed get the nearest free places.
    actuators, links, joints, pivots = LabelPlan(), LabelPlan(), LabelPlan(), LabelPlan()
    for link in machine.links:
        pts = _link_points(machine, frames, link.name)
        if len(pts) > 1:
            origin = pts[0]
            for p in pts[1:]:
                ax.plot([origin[0], p[0]], [origin[1], p[1]], color="0.35", lw=5, solid_capstyle="round", zorder=2)
                actuators.segment(origin, p)
        links.label(link.name, np.mean(pts, axis=0), fontsize=9, zorder=6)
        if link.parent is not None:
            o = frames.position[link.name][:2]
            ax.plot(*o, "o", ms=8, mfc="white", mec="black", zorder=5)
            actuators.marker(o)
            joints.label(f"{link.joint} ({link.joint_kind})", o, fontsize=7, zorder=6)
    orange = {"fontsize": 8, "color": "tab:orange", "zorder": 6}
    for chain in machine.chains:
        if chain.kind == "direct":
            link = machine.joint_link(chain.joint)
            start = frames.position[str(link.parent)] + frames.rotation[str(link.parent)] @ np.asarray(
                link.joint_frame.position
            )
            slide = frames.position[link.name]
            ax.plot([start[0], slide[0]], [start[1], slide[1]], color="tab:orange", lw=3, zorder=4)
            actuators.segment(start, slide)
            actuators.label(f"{chain.name} actuator (direct), stroke {chain.actuator.stroke:g} m", slide, **orange)
            continue
        pins = pin_positions(machine, frames, chain.name)
        end = pins["pin"] if chain.kind == "linkage" else pins["end"]
        base = pins["base"]
        ax.plot([base[0], end[0]], [base[1], end[1]], color="tab:orange", lw=3, zorder=3)
        actuators.segment(base, end)
        actuators.label(f"{chain.name} actuator, stroke {chain.actuator.stroke:g} m", 0.5 * (base + end), **orange)
        if chain.kind == "linkage":
            for a, b in (("rocker", "pin"), ("pin", "coupler")):
                ax.plot([pins[a][0], pins[b][0]], [pins[a][1], pins[b][1]], color="tab:green", lw=2.5, zorder=3)
                actuators.segment(pins[a], pins[b])
        for role, p in pins.items():
            if role == "hinge":
                continue
            ax.plot(p[0], p[1], "o", ms=5, color="black", zorder=5)
            actuators.marker(p)
            pivots.label(f"{chain.name}.{role}", p, fontsize=7, zorder=6)
    tcp = frames.tcp_position
    ax.plot(tcp[0], tcp[1], "*", ms=12, color="tab:red", zorder=6)
    actuators.marker(tcp)
    actuators.label("TCP", tcp, color="tab:red", fontsize=9, zorder=6)
    ax.plot([], [], "s", color=(0.35, 0.55, 0.85, 0.4), label="TCP workspace over the working ranges")
    ax.legend(loc="best", fontsize=8)
    ax.use_sticky_edges = False  # the image's extent is not the frame: a margin around the workspace and labels
    ax.margins(0.05)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m] (up)")
    ax.set_title(f"{machine.name}: joints at the middle of their working ranges")
    ax.grid(True, alpha=0.3)
    plan = LabelPlan(
        actuators.labels + links.labels + joints.labels + pivots.labels, actuators.markers, actuators.segments
    )
    place_labels(fig, ax, plan)
    return fig


def save_drawing(machine: Machine, path: Path) -> Path:
    """Draw the machine and write the PNG atomically."""
    return save_png(draw_machine(machine), path)

"""EMLA efficiency maps over load force and rod velocity in all four quadrants (the seed's Fig. Eff).

The map data are pure numpy (:func:`efficiency_map`); plotting uses matplotlib's object API with
the Agg canvas (no pyplot, no display, no global backend switch); CSV/NPZ writers dump the grid.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.envelope import ENVELOPE_LIMIT_NAMES
from hiab_sim.emla.model import operating_point, peak_force, top_speed
from hiab_sim.errors import InvalidInputError
from hiab_sim.style import colour

#: The envelope's limits in words (names of :data:`hiab_sim.emla.envelope.ENVELOPE_LIMIT_NAMES`).
ENVELOPE_WORDS = {"peak_torque": "motor peak torque", "rated_speed": "rated speed", "voltage": "drive voltage"}
#: The colour bar's label: the efficiency in each quadrant.
EFFICIENCY_LABEL = "efficiency: $f_x v_x / P_{elec}$ motoring, $P_{elec} / f_x v_x$ generating"
#: Filled efficiency levels of the map; the labelled contour lines are a subset.
EFFICIENCY_LEVELS: tuple[float, ...] = (0.0, 0.3, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.92, 0.94, 0.96, 1.0)
LABELLED_LEVELS: tuple[float, ...] = (0.5, 0.7, 0.8, 0.85, 0.9, 0.92, 0.94)
#: Efficiency field under design overlays: light greys (darker = more efficient), so that the
#: designs' colours (:mod:`hiab_sim.style`) are the only colours on the map.
# Warm light field (cream to sand) under the designs' blue and green lines: no grey-on-grey, no clash with them.
DESIGN_BACKGROUND = ListedColormap(colormaps["YlOrBr"](np.linspace(0.0, 0.35, 256)), name="light_sand")


@dataclass(frozen=True)
class EfficiencyMap:
    """Efficiency and power of one EMLA on a (force, velocity) grid at zero acceleration.

    Attributes:
        actuator: Actuator name.
        force: Load force samples f_x [N], shape ``(nf,)``.
        velocity: Rod velocity samples v_x [m/s], shape ``(nv,)``.
        efficiency: eta on the grid, shape ``(nf, nv)`` (see :func:`hiab_sim.emla.model.efficiency`).
        electrical_power: P_elec [W], shape ``(nf, nv)``.
        mechanical_power: f_x v_x [W], shape ``(nf, nv)``.
        margins: Envelope margins, shape ``(3, nf, nv)``.
        within_envelope: Feasibility mask, shape ``(nf, nv)``.
        peak_force: :func:`~hiab_sim.emla.model.peak_force` [N].
        top_speed: :func:`~hiab_sim.emla.model.top_speed` [m/s].
        hydraulic_push_force: Push force of the replaced hydraulic cylinder [N] or None.
        hydraulic_pull_force: Pull force of the replaced hydraulic cylinder [N] or None.
        loss_options: Which optional drive losses are on (:meth:`~hiab_sim.emla.losses.DriveLosses.describe`).

    """

    actuator: str
    force: NDArray[np.float64]
    velocity: NDArray[np.float64]
    efficiency: NDArray[np.float64]
    electrical_power: NDArray[np.float64]
    mechanical_power: NDArray[np.float64]
    margins: NDArray[np.float64]
    within_envelope: NDArray[np.bool_]
    peak_force: float
    top_speed: float
    hydraulic_push_force: float | None
    hydraulic_pull_force: float | None
    loss_options: str = "drive losses: off (paper model)"


def efficiency_map(params: EmlaParams, n_force: int = 161, n_velocity: int = 161, span: float = 1.15) -> EfficiencyMap:
    """Evaluate the EMLA on a symmetric grid covering ``span`` times its peak force and top speed.

    Args:
        params: The actuator.
        n_force: Number of force samples (>= 3).
        n_velocity: Number of velocity samples (>= 3).
        span: Grid half-width as a multiple of the envelope's extent (> 1 so the envelope shows).

    """
    if n_force < 3:
        raise InvalidInputError("n_force", n_force, "must be >= 3")
    if n_velocity < 3:
        raise InvalidInputError("n_velocity", n_velocity, "must be >= 3")
    if not span > 1.0:
        raise InvalidInputError("span", span, "must be > 1")
    f_max = span * params.transmission_ratio * params.motor.peak_torque
    v_max = span * top_speed(params)
    force = np.linspace(-f_max, f_max, n_force)
    velocity = np.linspace(-v_max, v_max, n_velocity)
    ff, vv = np.meshgrid(force, velocity, indexing="ij")
    op = operating_point(params, ff, vv, 0.0, exact=True)
    return EfficiencyMap(
        actuator=params.name,
        force=force,
        velocity=velocity,
        efficiency=op.efficiency,
        electrical_power=op.electrical_power,
        mechanical_power=op.mechanical_power,
        margins=op.margins,
        within_envelope=op.within_envelope,
        peak_force=peak_force(params),
        top_speed=top_speed(params),
        hydraulic_push_force=params.hydraulic_push_force,
        hydraulic_pull_force=params.hydraulic_pull_force,
        loss_options=params.losses.describe(),
    )


def plot_efficiency_map(
    emap: EfficiencyMap,
    operating_points: tuple[ArrayLike, ArrayLike] | None = None,
    ax: Axes | None = None,
    designs: Mapping[str, tuple[ArrayLike, ArrayLike]] | None = None,
    losses_in_title: bool = True,
    colorbar: bool = True,
) -> Figure:
    """Draw the efficiency map: filled contours with labelled levels, the envelope and references.

    Outside the envelope the map is blank. The title names the optional drive losses that are on
    (the map uses their exact forms). In the generating quadrants (f_x v_x < 0) the colour is
    the generating efficiency P_elec / (f_x v_x) = |P_elec| / |f_x v_x|; grey hatching marks where
    the drive still draws power there (losses exceed the returned power).

    Args:
        emap: Map data from :func:`efficiency_map`.
        operating_points: Optional (f_x [N], v_x [m/s]) arrays of one shape to overlay as dots.
        ax: Axes to draw into; a new Agg-backed figure is made when None.
        designs: Optional design name (``initial``, ``optimal``, ``rounded``...) -> (f_x [N],
            v_x [m/s]): each design's operating points in its colour and marker of
            :mod:`hiab_sim.style`, over a light efficiency field; the initial design's line is drawn
            over the optimal one (thinner, dash-dot), so both show where they coincide.
        losses_in_title: Name the drive losses in the axes' title (False: the caller names them once
            for several maps).
        colorbar: Draw the efficiency colour bar (False: the caller draws one for several maps).

    Returns:
        The figure holding the axes.

    """
    if ax is None:
        fig = Figure(figsize=(7.5, 5.8), layout="constrained")
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
    else:
        fig = ax.get_figure()  # type: ignore[assignment]
    v = emap.velocity
    f_kn = emap.force / 1e3
    eta = np.where(emap.within_envelope, emap.efficiency, np.nan)
    cmap = DESIGN_BACKGROUND if designs else colormaps["viridis"]
    filled = ax.contourf(v, f_kn, np.clip(eta, 0.0, 1.0), levels=list(EFFICIENCY_LEVELS), cmap=cmap)
    lines = ax.contour(v, f_kn, eta, levels=list(LABELLED_LEVELS), colors="0.3" if designs else "white", linewidths=0.7)
    ax.clabel(lines, fmt="%.2f", fontsize=7)
    drawing = emap.within_envelope & (emap.mechanical_power < 0) & (emap.efficiency < 0)
    if np.any(drawing):
        ax.contourf(v, f_kn, drawing.astype(float), levels=[0.5, 1.5], colors="0.6", hatches=["///"], alpha=0.9)
    ax.contour(v, f_kn, emap.margins.min(axis=0), levels=[0.0], colors="black", linewidths=2.0)
    limits = ", ".join(ENVELOPE_WORDS.get(n, n.replace("_", " ")) for n in ENVELOPE_LIMIT_NAMES)
    ax.plot([], [], color="black", linewidth=2.0, label=f"envelope ({limits})")
    if np.any(drawing):
        ax.fill_between([], [], color="0.6", hatch="///", label="generating, drive still draws power")
    if emap.hydraulic_push_force is not None:
        ax.axhline(emap.hydraulic_push_force / 1e3, color=colour("hydraulic"), linestyle="--", linewidth=1.2)
        ax.plot([], [], color=colour("hydraulic"), linestyle="--", label="hydraulic cylinder push / pull")
    if emap.hydraulic_pull_force is not None:
        ax.axhline(-emap.hydraulic_pull_force / 1e3, color=colour("hydraulic"), linestyle="--", linewidth=1.2)
    if operating_points is not None:
        f_op, v_op = _points(operating_points, "operating_points")
        ax.plot(v_op, f_op / 1e3, ".", color="tab:orange", markersize=3, label="operating points")
    for name, points in (designs or {}).items():  # the motion's path through the map: a line per design
        f_op, v_op = _points(points, f"designs[{name!r}]")
        ax.plot(
            v_op, f_op / 1e3, color=colour(name), linewidth=2.6 if name == "optimal" else 1.4,
            linestyle="-" if name == "optimal" else "-.", zorder=3 if name == "optimal" else 4,  # dashed: hydraulic
            label=f"{name} design: operating points over the motion",
        )  # fmt: skip
    ax.axhline(0.0, color="0.3", linewidth=0.5)
    ax.axvline(0.0, color="0.3", linewidth=0.5)
    for sx, sy, text in (
        (1, 1, "motoring"),
        (-1, -1, "motoring"),
        (-1, 1, "generating"),
        (1, -1, "generating"),
    ):
        ax.text(
            0.5 + 0.47 * sx, 0.5 + 0.47 * sy, text, transform=ax.transAxes, fontsize=8, color="0.25",
            ha="right" if sx > 0 else "left", va="top" if sy > 0 else "bottom",
        )  # fmt: skip
    ax.set_xlabel("rod velocity $v_x$ [m/s]")
    ax.set_ylabel("load force $f_x$ [kN]")
    title = f"EMLA efficiency, {emap.actuator}: peak {emap.peak_force / 1e3:.1f} kN, top {emap.top_speed:.3f} m/s"
    if losses_in_title:
        title += "\n" + "\n".join(textwrap.wrap(emap.loss_options, 95))
    ax.set_title(title, fontsize=9)
    title_lines = title.count("\n") + 1
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.035 + 0.035 * title_lines), ncol=2, fontsize=7, frameon=False)
    if colorbar:
        fig.colorbar(filled, ax=ax, label=EFFICIENCY_LABEL)
    return fig


def _points(points: tuple[ArrayLike, ArrayLike], field: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(f_x, v_x) as flat float arrays of one shape."""
    f_op = np.asarray(points[0], dtype=float).ravel()
    v_op = np.asarray(points[1], dtype=float).ravel()
    if f_op.shape != v_op.shape:
        raise InvalidInputError(field, f"shapes {f_op.shape}, {v_op.shape}", "must match")
    return f_op, v_op


def save_csv(emap: EfficiencyMap, path: str | Path) -> None:
    """Write the map as CSV, one row per grid point, SI units named in the header."""
    ff, vv = np.meshgrid(emap.force, emap.velocity, indexing="ij")
    columns = [ff, vv, emap.efficiency, emap.electrical_power, emap.mechanical_power]
    columns += [emap.within_envelope.astype(float), *emap.margins]
    header = "force_N,velocity_m_per_s,efficiency,electrical_power_W,mechanical_power_W,within_envelope,"
    header += ",".join(f"margin_{name}" for name in ENVELOPE_LIMIT_NAMES)
    table = np.column_stack([c.ravel() for c in columns])
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.10g")


def save_npz(emap: EfficiencyMap, path: str | Path) -> None:
    """Write the map to a compressed NPZ file: a key per :class:`EfficiencyMap` field, ``margin_names`` beside.

    A field that is ``None`` (a hydraulic force the actuator has none of) is left out; ``margin_names``
    names the rows of ``margins`` (:data:`hiab_sim.emla.envelope.ENVELOPE_LIMIT_NAMES`).
    """
    arrays = {f.name: np.asarray(getattr(emap, f.name)) for f in fields(emap) if getattr(emap, f.name) is not None}
    np.savez_compressed(path, margin_names=np.array(ENVELOPE_LIMIT_NAMES), **arrays)  # type: ignore[arg-type]

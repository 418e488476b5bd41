"""Placing a drawing's labels where they cover neither each other nor the points they name.

A machine's pivots sit close together (a hinge, two actuator pins and a joint within a few
centimetres on the XS 031), so labels at one fixed offset overprint each other. The labels here
are collected first and placed once the axes' scale is final: each in turn (the order they were
added, most important first) at the candidate offset of least cost, where a candidate is one of
:data:`DIRECTIONS` around the anchor at one of :data:`RADII_PT`. The cost counts, in display space,
overlaps with labels already placed and with marker points (:data:`OVERLAP`, each), link and
actuator segments crossing the label (:data:`CROSSING`, each), any part outside the axes
(:data:`OUTSIDE`), a leader line crossing a label placed before it (:data:`LEADER`), and the
offset's radius (so the nearest free place wins). A label placed beyond the second radius gets a
thin leader line, and every label a light backing (:data:`BACKING`) so a line under it leaves it
readable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from hiab_sim.arrays import Array

#: Offsets from the anchor [pt] tried, nearest first.
RADII_PT = (6.0, 12.0, 20.0, 30.0, 44.0)
#: Directions tried at each radius [rad], counter-clockwise from +x, starting up and to the right.
DIRECTIONS = tuple(math.radians(a) for a in (45, 135, 315, 225, 90, 270, 0, 180, 20, 160, 340, 200, 70, 110, 290, 250))
#: Cost of one overlap with a placed label or a marker point.
OVERLAP = 100.0
#: Cost of one segment crossing the label.
CROSSING = 12.0
#: Cost of a leader line crossing a label placed before it.
LEADER = 40.0
#: Cost of a label reaching outside the axes.
OUTSIDE = 1000.0
#: Half-size of the square kept free around a marker point [pt].
MARKER_PT = 3.5
#: A label's backing: a light box, so a line it must cross leaves the text readable.
BACKING = {"boxstyle": "round,pad=0.15", "fc": (1.0, 1.0, 1.0, 0.75), "ec": "none"}  # white, 75 % opaque
#: Padding around a label's text box [px] when testing overlaps.
PAD_PX = 2.0


@dataclass
class LabelPlan:
    """Labels to place on one axes: text, anchor [data units] and the ``annotate`` style of each."""

    labels: list[tuple[str, tuple[float, float], dict[str, Any]]] = field(default_factory=list)
    markers: list[tuple[float, float]] = field(default_factory=list)
    segments: list[tuple[tuple[float, float], tuple[float, float]]] = field(default_factory=list)

    def label(self, text: str, at: Array | tuple[float, float], **style: Any) -> None:
        """Add a label at ``at`` (data units); ``style`` goes to ``annotate`` (fontsize, colour, zorder)."""
        self.labels.append((text, (float(at[0]), float(at[1])), style))

    def marker(self, at: Array | tuple[float, float]) -> None:
        """A point a label must not cover (a pivot, a joint, the TCP)."""
        self.markers.append((float(at[0]), float(at[1])))

    def segment(self, a: Array | tuple[float, float], b: Array | tuple[float, float]) -> None:
        """A drawn line a label should not cross (a link or an actuator)."""
        self.segments.append(((float(a[0]), float(a[1])), (float(b[0]), float(b[1]))))


def _alignment(angle: float) -> tuple[str, str]:
    c, s = math.cos(angle), math.sin(angle)
    ha = "left" if c > 0.3 else "right" if c < -0.3 else "center"
    va = "bottom" if s > 0.3 else "top" if s < -0.3 else "center"
    return ha, va


def _box(anchor: Array, offset: Array, size: Array, ha: str, va: str) -> Array:
    """The label's box (x0, y0, x1, y1) [px] with its alignment point at ``anchor + offset``."""
    x, y = anchor + offset
    w, h = size
    x0 = x if ha == "left" else x - w if ha == "right" else x - 0.5 * w
    y0 = y if va == "bottom" else y - h if va == "top" else y - 0.5 * h
    return np.array([x0 - PAD_PX, y0 - PAD_PX, x0 + w + PAD_PX, y0 + h + PAD_PX])


def _overlaps(box: Array, boxes: Array) -> int:
    if len(boxes) == 0:
        return 0
    return int(
        np.sum((box[0] < boxes[:, 2]) & (boxes[:, 0] < box[2]) & (box[1] < boxes[:, 3]) & (boxes[:, 1] < box[3]))
    )


def _crossings(box: Array, segments: Array) -> int:
    """Segments (S, 2, 2) [px] that pass through the box, by sampling each at 24 points."""
    if len(segments) == 0:
        return 0
    t = np.linspace(0.0, 1.0, 24)[None, :, None]
    points = segments[:, :1, :] + t * (segments[:, 1:, :] - segments[:, :1, :])  # (S, 24, 2)
    inside = (
        (points[..., 0] > box[0]) & (points[..., 0] < box[2]) & (points[..., 1] > box[1]) & (points[..., 1] < box[3])
    )
    return int(np.sum(np.any(inside, axis=1)))


def place_labels(fig: Figure, ax: Axes, plan: LabelPlan) -> None:
    """Draw the plan's labels at their cheapest free places (module docstring); freezes the figure's layout.

    The figure is drawn once to fix the axes' scale; its layout engine is then switched off, so the
    labels' places in display space stay what they were chosen for when the figure is saved.
    """
    fig.canvas.draw()
    fig.set_layout_engine("none")
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    to_px = ax.transData.transform
    px_per_pt = fig.dpi / 72.0
    frame = ax.get_window_extent(renderer)
    half = MARKER_PT * px_per_pt
    markers = to_px(np.array(plan.markers)) if plan.markers else np.zeros((0, 2))
    marker_boxes = np.column_stack([markers - half, markers + half]) if len(markers) else np.zeros((0, 4))
    segments = to_px(np.array(plan.segments).reshape(-1, 2)).reshape(-1, 2, 2) if plan.segments else np.zeros((0, 2, 2))
    placed: list[Array] = []
    for text, at, style in plan.labels:
        probe = ax.text(0.0, 0.0, text, fontsize=style.get("fontsize", 8))
        extent = probe.get_window_extent(renderer)
        probe.remove()
        size = np.array([extent.width, extent.height])
        anchor = to_px(np.array(at))
        placed_boxes = np.array(placed).reshape(-1, 4)  # the labels placed so far, once per label
        best: tuple[float, float, float, str, str] | None = None
        for radius in RADII_PT:
            for angle in DIRECTIONS:
                offset = radius * px_per_pt * np.array([math.cos(angle), math.sin(angle)])
                ha, va = _alignment(angle)
                box = _box(anchor, offset, size, ha, va)
                cost = OVERLAP * (_overlaps(box, placed_boxes) + _overlaps(box, marker_boxes))
                cost += CROSSING * _crossings(box, segments)
                if radius > RADII_PT[1]:  # its leader line should not cross the labels placed before it
                    line = np.array([[anchor, anchor + offset]])
                    cost += LEADER * sum(_crossings(b, line) for b in placed)
                outside = box[0] < frame.x0 or box[1] < frame.y0 or box[2] > frame.x1 or box[3] > frame.y1
                cost += OUTSIDE * outside + 0.05 * radius
                if best is None or cost < best[0]:
                    best = (cost, radius, angle, ha, va)
        assert best is not None  # RADII_PT and DIRECTIONS are not empty
        _, radius, angle, ha, va = best
        offset_pt = (radius * math.cos(angle), radius * math.sin(angle))
        leader = {"arrowstyle": "-", "lw": 0.5, "color": "0.4"} if radius > RADII_PT[1] else None
        ax.annotate(
            text,
            at,
            xytext=offset_pt,
            textcoords="offset points",
            ha=ha,
            va=va,
            arrowprops=leader,
            bbox=BACKING,
            **style,
        )
        placed.append(_box(anchor, np.array(offset_pt) * px_per_pt, size, ha, va))

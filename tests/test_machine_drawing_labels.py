"""``machine show``'s drawing: every label readable, none over another or over a pivot, joint or the TCP."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from matplotlib.text import Annotation, Text

from hiab_sim.machine.drawing import draw_machine
from hiab_sim.machine.loader import load_machine

PRESETS = Path(str(resources.files("hiab_sim") / "presets"))


def _boxes(name: str) -> tuple[list[str], np.ndarray, np.ndarray]:
    """The drawing's label texts, their boxes (N, 4) [px] and its marker points (M, 2) [px]."""
    fig = draw_machine(load_machine(PRESETS / name))
    ax = fig.axes[0]
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    fig.canvas.draw()
    labels = [t for t in ax.texts if isinstance(t, Annotation)]
    # the text's own box: an Annotation's extent would include its leader line
    boxes = np.array([[b.x0, b.y0, b.x1, b.y1] for b in (Text.get_window_extent(t, renderer) for t in labels)])
    points = []
    for line in ax.lines:  # the pivots, joints and the TCP: single-point marker lines
        x, y = line.get_xdata(), line.get_ydata()
        if len(np.atleast_1d(x)) == 1 and line.get_marker() not in (None, "None", ""):
            points.append(ax.transData.transform((float(np.atleast_1d(x)[0]), float(np.atleast_1d(y)[0]))))
    return [t.get_text() for t in labels], boxes, np.array(points)


@pytest.mark.parametrize("name", ["xs031_machine.yaml", "exact_excavator.yaml"])
def test_no_two_labels_of_a_shipped_machine_overlap(name: str) -> None:
    """The XS 031's hinge, pins and joint lie within centimetres: their labels still stand apart."""
    texts, boxes, _ = _boxes(name)
    assert len(texts) > 10
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            a, b = boxes[i], boxes[j]
            overlap = a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]
            assert not overlap, f"{texts[i]!r} over {texts[j]!r}"


@pytest.mark.parametrize("name", ["xs031_machine.yaml", "exact_excavator.yaml"])
def test_no_label_covers_a_pivot_joint_or_the_tcp(name: str) -> None:
    """Every marker point lies outside every label's box (its own label's included)."""
    texts, boxes, points = _boxes(name)
    assert len(points) > 5
    for text, box in zip(texts, boxes, strict=True):
        inside = (points[:, 0] > box[0]) & (points[:, 0] < box[2]) & (points[:, 1] > box[1]) & (points[:, 1] < box[3])
        assert not inside.any(), f"{text!r} covers a marker at {points[inside][0]} px"


def test_every_link_chain_and_joint_is_named_once() -> None:
    """The placement keeps every label: links, joints, actuators, pins and the TCP, each once."""
    machine = load_machine(PRESETS / "exact_excavator.yaml")
    texts, _, _ = _boxes("exact_excavator.yaml")
    assert len(texts) == len(set(texts))
    expected = {link.name for link in machine.links} | {"TCP"}
    expected |= {f"{link.joint} ({link.joint_kind})" for link in machine.links if link.parent is not None}
    assert expected <= set(texts)
    assert all(any(t.startswith(f"{c.name} actuator") for t in texts) for c in machine.chains)

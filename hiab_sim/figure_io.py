"""One way to draw and write a figure: an off-screen Agg figure, saved as PNG atomically (no pyplot state)."""

from __future__ import annotations

import io
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from hiab_sim.atomic_io import write_atomic


def new_figure(size: tuple[float, float]) -> Figure:
    """A constrained-layout figure of ``size`` [in] on its own Agg canvas (no display, no global state)."""
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_png(fig: Figure, path: Path, dpi: int = 120) -> Path:
    """Write ``fig`` as PNG to ``path`` atomically (temp file + rename) and return the path."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    write_atomic(path, buffer.getvalue())
    return path

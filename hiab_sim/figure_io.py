"""The one figure writer: an off-screen Agg figure, saved as PNG atomically (no pyplot, no global state).

Every figure of hiab-sim is made by :func:`new_figure` and leaves through :func:`save_png` (a file)
or :func:`png_bytes` (bytes for a caller that writes several files atomically itself).
"""

from __future__ import annotations

import io
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from hiab_sim.atomic_io import write_atomic

#: Resolution of every written figure [dots per inch].
DPI = 120


def new_figure(size: tuple[float, float]) -> Figure:
    """A constrained-layout figure of ``size`` [in] on its own Agg canvas (no display, no global state)."""
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def png_bytes(fig: Figure, dpi: int = DPI) -> bytes:
    """The figure as PNG bytes."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def save_png(fig: Figure, path: Path, dpi: int = DPI) -> Path:
    """Write ``fig`` as PNG to ``path`` atomically (temp file + rename) and return the path."""
    write_atomic(Path(path), png_bytes(fig, dpi))
    return Path(path)

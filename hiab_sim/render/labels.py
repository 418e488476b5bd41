"""Text captions stamped onto rendered frames (MuJoCo's off-screen renderer draws no free text).

A caption is rasterised once with matplotlib's Agg backend and alpha-blended into every frame,
which costs a fraction of a millisecond per frame.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

Image = NDArray[np.uint8]


def caption_bitmap(text: str, rgb: Sequence[float], height: int = 18) -> NDArray[np.float32]:
    """RGBA bitmap (h, w, 4) in [0, 1] of ``text`` in colour ``rgb``, about ``height`` px tall."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    dpi = 100.0
    figure = Figure(figsize=(max(len(text), 1) * height * 0.9 / dpi, height * 1.8 / dpi), dpi=dpi)
    figure.patch.set_alpha(0.0)  # transparent: only the glyphs are stamped, not a white box
    canvas = FigureCanvasAgg(figure)
    figure.text(0.02, 0.5, text, color=tuple(rgb), fontsize=height * 0.75 * 72 / dpi, weight="bold", va="center")
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba(), dtype=np.float32) / 255.0
    alpha = rgba[..., 3]
    rows, cols = np.nonzero(alpha > 0.02)
    if len(rows) == 0:
        return np.zeros((1, 1, 4), dtype=np.float32)
    return np.ascontiguousarray(rgba[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1])


#: Caption box: padding [px] and how much of the scene shows through its white [0, 1].
BOX_PAD = 4
BOX_SHOW_THROUGH = 0.15


def stamp(image: Image, bitmap: NDArray[np.float32], top: int = 8, left: int = 8, box: bool = True) -> None:
    """Alpha-blend ``bitmap`` onto ``image`` (H, W, 3) in place, clipped to the image.

    With ``box`` the text sits on a nearly white box (:data:`BOX_SHOW_THROUGH`), so it stays
    readable over any part of the scene.
    """
    height = min(bitmap.shape[0], image.shape[0] - top)
    width = min(bitmap.shape[1], image.shape[1] - left)
    if height <= 0 or width <= 0:
        return
    if box:
        r0, c0 = max(top - BOX_PAD, 0), max(left - BOX_PAD, 0)
        r1, c1 = min(top + height + BOX_PAD, image.shape[0]), min(left + width + BOX_PAD, image.shape[1])
        region = image[r0:r1, c0:c1].astype(np.float32)
        image[r0:r1, c0:c1] = (BOX_SHOW_THROUGH * region + (1.0 - BOX_SHOW_THROUGH) * 255.0 + 0.5).astype(np.uint8)
    patch = image[top : top + height, left : left + width].astype(np.float32)
    source = bitmap[:height, :width]
    alpha = source[..., 3:4]
    blended = patch * (1.0 - alpha) + source[..., :3] * 255.0 * alpha
    image[top : top + height, left : left + width] = np.clip(blended + 0.5, 0, 255).astype(np.uint8)

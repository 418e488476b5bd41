"""Central differences of a whole NLP in z: the steps every gradient test takes."""

from __future__ import annotations

import numpy as np


def central_steps(z: np.ndarray, j: int, relative: float = 1e-6) -> tuple[np.ndarray, np.ndarray, float]:
    """``z`` stepped by +h and -h in entry ``j``, h = ``relative`` max(1, |z_j|): (up, down, h)."""
    h = relative * max(1.0, abs(z[j]))
    up, down = z.copy(), z.copy()
    up[j] += h
    down[j] -= h
    return up, down, h

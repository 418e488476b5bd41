"""Quadrature over time samples shared by the energy integrals (one definition of the trapezoid rule)."""

from __future__ import annotations

import numpy as np

from hiab_sim.arrays import Array


def trapezoid(y: Array, t: Array) -> Array:
    """Trapezoid rule integral of ``y`` over the samples ``t`` [s] along the last axis.

    Written out because ``np.trapz``/``np.trapezoid`` changed names between numpy 1.26 and 2.x.
    A 1-D ``y`` gives a 0-d array (wrap with ``float``).
    """
    y = np.asarray(y, dtype=float)
    return np.asarray(0.5 * np.sum((y[..., 1:] + y[..., :-1]) * np.diff(t), axis=-1))

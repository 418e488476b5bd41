"""Amplitude-invariant Park transform between phase (abc) and rotor (dq0) quantities.

Conventions (eqs. ``Park_Transformation``, ``abc_to_dq``): x_dq0 = (2/3) P(theta_e) x_abc, so a
balanced phase set of peak amplitude X maps to |x_dq| = sqrt(x_d^2 + x_q^2) = X. Power is then
p = v_a i_a + v_b i_b + v_c i_c = 3/2 (v_d i_d + v_q i_q) + 3 v_0 i_0, and the line-to-line rms
voltage of a balanced set is sqrt(3) X / sqrt(2) = sqrt(3/2) |v_dq|.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

_SHIFTS = np.array([0.0, -2.0 * np.pi / 3.0, 2.0 * np.pi / 3.0])


def park_matrix(theta_e: ArrayLike) -> NDArray[np.float64]:
    """Return the Park matrix P(theta_e) of eq. ``Park_Transformation``.

    Args:
        theta_e: Electrical angle [rad], any shape ``S``.

    Returns:
        Array of shape ``S + (3, 3)``; rows d, q, 0 and columns a, b, c.

    """
    angle = np.asarray(theta_e, dtype=float)[..., None] + _SHIFTS
    zero_row = np.full(angle.shape, 0.5)
    return np.stack([np.cos(angle), -np.sin(angle), zero_row], axis=-2)


def abc_to_dq0(x_abc: ArrayLike, theta_e: ArrayLike) -> NDArray[np.float64]:
    """Transform phase quantities to the rotor frame, x_dq0 = (2/3) P x_abc (eq. ``abc_to_dq``).

    Args:
        x_abc: Phase values (voltages [V] or currents [A]), shape ``(3,) + S``.
        theta_e: Electrical angle [rad], shape broadcastable to ``S``.

    Returns:
        ``(d, q, 0)`` components, shape ``(3,) + S``.

    """
    x = np.moveaxis(np.asarray(x_abc, dtype=float), 0, -1)
    p = park_matrix(theta_e)
    return np.moveaxis((2.0 / 3.0) * np.einsum("...ij,...j->...i", p, x), -1, 0)


def dq0_to_abc(x_dq0: ArrayLike, theta_e: ArrayLike) -> NDArray[np.float64]:
    """Inverse of :func:`abc_to_dq0`: x_abc = ((2/3) P)^-1 x_dq0.

    The inverse is x_k = x_d cos(theta_e - s_k) - x_q sin(theta_e - s_k) + x_0 with s_k = 0, 2pi/3,
    -2pi/3 for phases a, b, c.

    Args:
        x_dq0: Rotor-frame values, shape ``(3,) + S``.
        theta_e: Electrical angle [rad], shape broadcastable to ``S``.

    Returns:
        Phase values, shape ``(3,) + S``.

    """
    x = np.moveaxis(np.asarray(x_dq0, dtype=float), 0, -1)
    p = park_matrix(theta_e)
    # (2/3 P)^-1 = P^T with its third column doubled to 1 (P has orthogonal rows of norm^2 3/2, 3/2, 3/4).
    inverse = np.swapaxes(p, -1, -2) * np.array([1.0, 1.0, 2.0])
    return np.moveaxis(np.einsum("...ij,...j->...i", inverse, x), -1, 0)


def dq0_power(v_dq0: ArrayLike, i_dq0: ArrayLike) -> NDArray[np.float64]:
    """Instantaneous three-phase power from rotor-frame values: 3/2 (v_d i_d + v_q i_q) + 3 v_0 i_0 [W]."""
    v = np.asarray(v_dq0, dtype=float)
    i = np.asarray(i_dq0, dtype=float)
    return np.asarray(1.5 * (v[0] * i[0] + v[1] * i[1]) + 3.0 * v[2] * i[2])


def line_voltage_rms(v_d: ArrayLike, v_q: ArrayLike) -> NDArray[np.float64]:
    """Line-to-line rms voltage of the balanced phase set with rotor-frame voltage (v_d, v_q) [V].

    With the amplitude-invariant transform the phase peak is sqrt(v_d^2 + v_q^2), the phase rms
    that over sqrt(2), and the line rms sqrt(3) times the phase rms: sqrt(3/2 (v_d^2 + v_q^2)).
    """
    vd = np.asarray(v_d, dtype=float)
    vq = np.asarray(v_q, dtype=float)
    return np.asarray(np.sqrt(1.5 * (vd * vd + vq * vq)))

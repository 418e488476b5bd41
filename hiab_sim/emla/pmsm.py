"""PMSM equations in the rotor (dq) frame, for any d-axis current and Ld != Lq (eq. ``dq0voltage``)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.emla.config import PmsmParams


def dq_voltages(
    motor: PmsmParams,
    i_d: ArrayLike,
    i_q: ArrayLike,
    motor_speed: ArrayLike,
    di_d: ArrayLike = 0.0,
    di_q: ArrayLike = 0.0,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return (V_d, V_q) [V] of eq. ``dq0voltage``.

    V_d = R_s i_d + L_d di_d/dt - p omega_m L_q i_q and
    V_q = R_s i_q + L_q di_q/dt + p omega_m (L_d i_d + Phi_PM).

    Args:
        motor: Motor parameters.
        i_d: d-axis current [A].
        i_q: q-axis current [A].
        motor_speed: Mechanical rotor speed omega_m [rad/s].
        di_d: d-axis current rate [A/s] (0 in steady state).
        di_q: q-axis current rate [A/s] (0 in steady state).

    """
    i_d = np.asarray(i_d, dtype=float)
    i_q = np.asarray(i_q, dtype=float)
    omega_e = motor.pole_pairs * np.asarray(motor_speed, dtype=float)
    r = motor.stator_resistance
    v_d = r * i_d + motor.Ld * np.asarray(di_d, dtype=float) - omega_e * motor.Lq * i_q
    v_q = r * i_q + motor.Lq * np.asarray(di_q, dtype=float) + omega_e * (motor.Ld * i_d + motor.flux_linkage)
    return v_d, v_q


def electromagnetic_torque(motor: PmsmParams, i_d: ArrayLike, i_q: ArrayLike) -> NDArray[np.float64]:
    """Return tau_m = 3/2 p i_q (Phi_PM + (L_d - L_q) i_d) [N m] (eq. ``dq0voltage``)."""
    i_d = np.asarray(i_d, dtype=float)
    i_q = np.asarray(i_q, dtype=float)
    return np.asarray(1.5 * motor.pole_pairs * i_q * (motor.flux_linkage + (motor.Ld - motor.Lq) * i_d))


def current_derivatives(
    motor: PmsmParams,
    i_d: ArrayLike,
    i_q: ArrayLike,
    motor_speed: ArrayLike,
    v_d: ArrayLike,
    v_q: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Solve eq. ``dq0voltage`` for (di_d/dt, di_q/dt) [A/s] given the applied voltages [V].

    This is the state equation of the current dynamics, used by transient checks.
    """
    i_d = np.asarray(i_d, dtype=float)
    i_q = np.asarray(i_q, dtype=float)
    omega_e = motor.pole_pairs * np.asarray(motor_speed, dtype=float)
    r = motor.stator_resistance
    di_d = (np.asarray(v_d, dtype=float) - r * i_d + omega_e * motor.Lq * i_q) / motor.Ld
    di_q = (np.asarray(v_q, dtype=float) - r * i_q - omega_e * (motor.Ld * i_d + motor.flux_linkage)) / motor.Lq
    return di_d, di_q

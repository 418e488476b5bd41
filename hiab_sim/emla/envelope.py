"""Feasible (f_x, v_x) envelope of one EMLA as smooth constraint margins g >= 0 and their gradients.

The limits behind the seed's force and velocity bounds (eqs. ``const_e``, ``const_f``):

* ``peak_torque``: g = 1 - (tau_m / tau_peak)^2, motor torque within the peak torque;
* ``rated_speed``: g = 1 - (omega_m / omega_rated)^2, motor speed within the rated speed;
* ``voltage``: g = 1 - (V_LL / V_max)^2 with V_LL = sqrt(3/2 (V_d^2 + V_q^2)) the line-to-line rms
  voltage of the amplitude-invariant dq voltages (back-EMF, resistive and inductive drops),
  V_max = ``max_line_voltage_rms``.

Squared ratios keep every margin a polynomial in (f_x, v_x, a_x) apart from the tanh friction, so
the margins are smooth everywhere (also at zero torque or speed); their zero sets are exactly the
limits |tau_m| = tau_peak, |omega_m| = omega_rated and V_LL = V_max, and each is O(1).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.drive import DriveState, drive_state

#: Row names of :func:`envelope_margins`, in row order.
ENVELOPE_LIMIT_NAMES: tuple[str, ...] = ("peak_torque", "rated_speed", "voltage")


def margins_from_state(params: EmlaParams, state: DriveState) -> NDArray[np.float64]:
    """Return the margins of :func:`envelope_margins` from an already computed drive state."""
    motor = params.motor
    g_torque = 1.0 - (state.motor_torque / motor.peak_torque) ** 2
    g_speed = 1.0 - (state.motor_speed / motor.rated_speed) ** 2
    g_voltage = 1.0 - 1.5 * (state.v_d**2 + state.v_q**2) / motor.max_line_voltage_rms**2
    return np.stack([g_torque, g_speed, g_voltage])


def envelope_margins(
    params: EmlaParams, force: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> NDArray[np.float64]:
    """Return constraint margins g (feasible where every g >= 0), one row per limit.

    Args:
        params: The actuator.
        force: Load force f_x [N].
        velocity: Rod velocity v_x [m/s].
        acceleration: Rod acceleration dv_x/dt [m/s^2].

    Returns:
        Dimensionless array of shape ``(len(ENVELOPE_LIMIT_NAMES),) + shape`` (rows in the order of
        :data:`ENVELOPE_LIMIT_NAMES`).

    """
    return margins_from_state(params, drive_state(params, force, velocity, acceleration))


def envelope_margin_partials(
    params: EmlaParams, force: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return the analytic partials (dg/df_x [1/N], dg/dv_x [s/m], dg/da_x [s^2/m]) of the margins.

    Each array has the shape of :func:`envelope_margins`' result.
    """
    state = drive_state(params, force, velocity, acceleration)
    motor = params.motor
    c_torque = -2.0 * state.motor_torque / motor.peak_torque**2
    c_speed = -2.0 * state.motor_speed / motor.rated_speed**2
    c_voltage = -3.0 / motor.max_line_voltage_rms**2
    partials = []
    for j in range(3):
        partials.append(
            np.stack(
                [
                    c_torque * state.d_motor_torque[j],
                    c_speed * state.d_motor_speed[j],
                    c_voltage * (state.v_d * state.d_v_d[j] + state.v_q * state.d_v_q[j]),
                ]
            )
        )
    return partials[0], partials[1], partials[2]


def within_envelope(
    params: EmlaParams, force: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> NDArray[np.bool_]:
    """Return True where every limit holds (all margins >= 0)."""
    return np.asarray(np.all(envelope_margins(params, force, velocity, acceleration) >= 0.0, axis=0))

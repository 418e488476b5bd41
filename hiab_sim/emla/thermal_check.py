"""Thermal limits of one EMLA along a trajectory, with gradients with respect to its load samples.

Composes the drive model (:func:`hiab_sim.emla.drive.drive_state`) with :mod:`hiab_sim.emla.thermal`
so the NLP can use the two limits as constraints on the actuator samples (f_x, v_x, a_x):

* RMS torque over the duty period: tau_rms <= tau_cont;
* periodic steady-state peak winding temperature: T_peak <= T_max.

The motor torque that heats the winding is s tau_m and the loss s P_cu (s: the holding brake's
release factor, 1 without a brake; see :mod:`hiab_sim.emla.losses`), the same copper loss that
:func:`hiab_sim.emla.operating_point` reports. Gradients are exact for the smooth model
(``exact=False``); with ``exact=True`` the values use the switched brake and kinked losses.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.drive import drive_state
from hiab_sim.emla.losses import brake_release
from hiab_sim.emla.thermal import Duty, ThermalParams, periodic_winding_temperature, rms_torque
from hiab_sim.errors import InvalidInputError


@dataclass(frozen=True)
class ThermalCheck:
    """Thermal state of one EMLA over a duty period.

    Attributes:
        rms_torque: tau_rms [N m].
        continuous_torque: tau_cont [N m].
        peak_temperature: Peak periodic winding temperature [deg C].
        max_temperature: T_max [deg C].
        d_rms: d tau_rms / d(f_x, v_x, a_x)_k, shape (3, K) [N m/N, N m s/m, N m s^2/m].
        d_peak: d T_peak / d(f_x, v_x, a_x)_k, shape (3, K) [K/N, K s/m, K s^2/m].

    """

    rms_torque: float
    continuous_torque: float
    peak_temperature: float
    max_temperature: float
    d_rms: Array
    d_peak: Array

    @property
    def torque_margin(self) -> float:
        """1 - tau_rms / tau_cont [-], feasible where >= 0."""
        return 1.0 - self.rms_torque / self.continuous_torque

    @property
    def temperature_margin(self) -> float:
        """T_max - T_peak [K], feasible where >= 0."""
        return self.max_temperature - self.peak_temperature


def thermal_check(
    params: EmlaParams,
    time: ArrayLike,
    force: ArrayLike,
    velocity: ArrayLike,
    acceleration: ArrayLike,
    duty: Duty,
    exact: bool = False,
) -> ThermalCheck:
    """Return the RMS torque and peak winding temperature of one EMLA over ``duty``, with gradients.

    Args:
        params: The actuator; ``params.thermal`` must be set (the EMLA file's ``thermal`` section).
        time: Cycle sample times [s], shape (K,), spanning ``duty.cycle_time``.
        force: Load force f_x [N], shape (K,).
        velocity: Rod velocity v_x [m/s], shape (K,).
        acceleration: Rod acceleration a_x [m/s^2], shape (K,).
        duty: Cycle and rest time (zero torque during the rest).
        exact: Exact brake switching and loss kinks (values only; gradients are the smooth model's).

    """
    thermal: ThermalParams | None = params.thermal
    if thermal is None:
        raise InvalidInputError(f"{params.name}.thermal", None, "must be given (EMLA file section 'thermal')")
    state = drive_state(params, force, velocity, acceleration, exact)
    v = np.broadcast_to(np.asarray(velocity, dtype=float), state.motor_torque.shape)
    s, ds = brake_release(params.losses, v, exact)
    tau = s * state.motor_torque
    d_tau = [s * dt for dt in state.d_motor_torque]
    d_tau[1] = d_tau[1] + ds * state.motor_torque
    rms, g_rms = rms_torque(time, tau, duty)
    motor = params.motor
    c = 1.5 * motor.stator_resistance / motor.torque_constant**2
    loss = s * c * state.motor_torque**2  # s P_cu, as operating_point reports it
    d_loss = [s * 2.0 * c * state.motor_torque * dt for dt in state.d_motor_torque]
    d_loss[1] = d_loss[1] + ds * c * state.motor_torque**2
    temp = periodic_winding_temperature(time, loss, thermal, duty)
    return ThermalCheck(
        rms_torque=rms,
        continuous_torque=thermal.continuous_torque,
        peak_temperature=temp.peak,
        max_temperature=thermal.max_winding_temperature,
        d_rms=np.stack([g_rms * d for d in d_tau]),
        d_peak=np.stack([temp.d_peak_d_loss * d for d in d_loss]),
    )

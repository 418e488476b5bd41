"""Motor thermal limits: RMS torque over a duty period and a first-order winding temperature model.

Duty: the cycle of duration T (samples t_0 = 0 .. t_{K-1} = T) is followed by a rest of
T_rest >= 0 at zero torque and zero loss (a holding brake or a set-down load), and repeats; the
duty period is P = T + T_rest (``cycles_per_hour`` n gives T_rest = 3600/n - T).

RMS torque over the duty period (trapezoid rule on the cycle's samples, zero during the rest):

    tau_rms = sqrt( int_0^T tau_m^2 dt / P ),   d tau_rms / d tau_k = w_k tau_k / (P tau_rms)

Copper loss per sample, with i_d = 0 (eq. ``dq0voltage``): P_cu = 3/2 R_s i_q^2,
i_q = tau_m / K_t, K_t = 3/2 p Phi_PM, so dP_cu/dtau_m = 3 R_s tau_m / K_t^2. R_s is the
configured (cold) resistance; the thermal resistance below is derived with the same R_s, so the
limit tau_rms <= tau_cont and the temperature limit agree at steady continuous load.

First-order winding model (one thermal capacitance C = tau_th / R_th to ambient):

    dtheta/dt = (R_th P(t) - theta) / tau_th,   theta = T_winding - T_ambient  [K]

With P linear between samples (h = t_{k+1} - t_k, E = exp(-h/tau_th), a = tau_th (1 - E) / h)
the exact step is theta_{k+1} = E theta_k + R_th [(a - E) P_k + (1 - a) P_{k+1}]. Over the cycle
theta_K = exp(-T/tau) theta_0 + beta, the rest decays it by exp(-T_rest/tau), and periodicity
gives theta_0 = exp(-T_rest/tau) beta / (1 - exp(-P/tau)). The peak is the largest sample
(the rest only cools); between samples the exact solution can exceed it by at most
(h/tau_th) max|R_th P - theta|, negligible for h << tau_th. theta is linear in the losses, so
d theta_j / d P_k is exact and cheap (:func:`temperature_sensitivity`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_fields, check_positive
from hiab_sim.errors import InvalidInputError


@dataclass(frozen=True)
class ThermalParams:
    """Continuous torque and first-order winding thermal model of one motor.

    Attributes:
        continuous_torque: tau_cont [N m] > 0, the RMS torque the motor carries indefinitely.
        thermal_resistance: R_th [K/W] > 0, winding to ambient.
        time_constant: tau_th [s] > 0, of the winding temperature.
        ambient_temperature: T_amb [deg C], finite.
        max_winding_temperature: T_max [deg C] > T_amb.
        label: Prefix of error messages (e.g. ``lift.thermal``).

    """

    continuous_torque: float
    thermal_resistance: float
    time_constant: float
    ambient_temperature: float
    max_winding_temperature: float
    label: str = "thermal"

    def __post_init__(self) -> None:
        check_fields(self, positive={"continuous_torque": "N m", "thermal_resistance": "K/W", "time_constant": "s"})
        if not math.isfinite(self.ambient_temperature):
            raise InvalidInputError(f"{self.label}.ambient_temperature", self.ambient_temperature, "must be finite")
        t_max = self.max_winding_temperature
        if not (math.isfinite(t_max) and t_max > self.ambient_temperature):
            raise InvalidInputError(
                f"{self.label}.max_winding_temperature",
                self.max_winding_temperature,
                f"must be finite and > ambient_temperature = {self.ambient_temperature:g} deg C",
                "deg C",
            )


@dataclass(frozen=True)
class Duty:
    """A cycle of ``cycle_time`` [s] followed by ``rest_time`` [s] at zero torque, repeated."""

    cycle_time: float
    rest_time: float = 0.0

    def __post_init__(self) -> None:
        check_positive("duty.cycle_time", self.cycle_time, "s")
        if not (math.isfinite(self.rest_time) and self.rest_time >= 0):
            raise InvalidInputError("duty.rest_time", self.rest_time, "must be finite and >= 0", "s")

    @classmethod
    def from_cycles_per_hour(cls, cycle_time: float, cycles_per_hour: float) -> Duty:
        """Return the duty of ``cycles_per_hour`` cycles of ``cycle_time`` [s] each hour."""
        check_positive("duty.cycle_time", cycle_time, "s")
        limit = 3600.0 / cycle_time
        if not (math.isfinite(cycles_per_hour) and 0 < cycles_per_hour <= limit):
            raise InvalidInputError("duty.cycles_per_hour", cycles_per_hour, f"must be in (0, {limit:g}]", "1/h")
        return cls(cycle_time, max(0.0, 3600.0 / cycles_per_hour - cycle_time))

    @property
    def period(self) -> float:
        """Duty period P = T + T_rest [s]."""
        return self.cycle_time + self.rest_time


def _cycle_weights(time: ArrayLike, duty: Duty) -> tuple[Array, Array]:
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.diff(t) > 0):
        raise InvalidInputError("time", f"shape {t.shape}", "must be strictly increasing with at least 2 samples")
    span = t[-1] - t[0]
    if not math.isclose(span, duty.cycle_time, rel_tol=1e-9):
        raise InvalidInputError("duty.cycle_time", duty.cycle_time, f"must equal the time grid's span {span:g} s", "s")
    h = np.diff(t)
    w = np.zeros_like(t)
    w[:-1] += 0.5 * h
    w[1:] += 0.5 * h
    return t - t[0], w


def cycle_time_grid(time: ArrayLike, duty: Duty) -> Array:
    """Return the cycle's sample times from 0 [s], checked to be increasing and to span ``duty.cycle_time``."""
    return _cycle_weights(time, duty)[0]


def rms_torque(time: ArrayLike, torque: ArrayLike, duty: Duty) -> tuple[float, Array]:
    """Return (tau_rms [N m], d tau_rms / d tau_k [1], shape (K,)) over the duty period.

    Args:
        time: Cycle sample times [s], shape (K,), spanning ``duty.cycle_time``.
        torque: Motor torque tau_m [N m], shape (K,).
        duty: Cycle and rest time.

    """
    _, w = _cycle_weights(time, duty)
    tau = np.asarray(torque, dtype=float)
    if tau.shape != w.shape:
        raise InvalidInputError("torque", f"shape {tau.shape}", f"must be ({w.size},)")
    rms = math.sqrt(float(w @ tau**2) / duty.period)
    grad = w * tau / (duty.period * rms) if rms > 0 else np.zeros_like(tau)
    return rms, grad


def copper_loss(stator_resistance: float, torque_constant: float, torque: ArrayLike) -> tuple[Array, Array]:
    """Return (P_cu [W], dP_cu/dtau_m [W/(N m)]) = (3/2 R_s (tau/K_t)^2, 3 R_s tau / K_t^2), i_d = 0."""
    tau = np.asarray(torque, dtype=float)
    return 1.5 * stator_resistance * (tau / torque_constant) ** 2, 3.0 * stator_resistance * tau / torque_constant**2


@dataclass(frozen=True)
class WindingTemperature:
    """Periodic steady state of the winding model over one cycle.

    Attributes:
        temperature: T_winding at the cycle's samples [deg C], shape (K,).
        peak: Largest sample [deg C].
        peak_index: Its index.
        d_peak_d_loss: d peak / d P_k [K/W], shape (K,) (of the sample at ``peak_index``).

    """

    temperature: Array
    peak: float
    peak_index: int
    d_peak_d_loss: Array


def _steps(t: Array, tau: float) -> tuple[Array, Array, Array]:
    h = np.diff(t)
    e = np.exp(-h / tau)
    a = tau * (-np.expm1(-h / tau)) / h
    return e, a - e, 1.0 - a


def periodic_winding_temperature(
    time: ArrayLike, loss: ArrayLike, thermal: ThermalParams, duty: Duty
) -> WindingTemperature:
    """Return the periodic steady-state winding temperature under the cycle's loss profile.

    Args:
        time: Cycle sample times [s], shape (K,), spanning ``duty.cycle_time``.
        loss: Loss heating the winding P_k [W] (e.g. :func:`copper_loss`), shape (K,).
        thermal: The motor's thermal model.
        duty: Cycle and rest time (zero loss during the rest).

    """
    t, _ = _cycle_weights(time, duty)
    p = np.asarray(loss, dtype=float)
    if p.shape != t.shape:
        raise InvalidInputError("loss", f"shape {p.shape}", f"must be ({t.size},)")
    tau, r = thermal.time_constant, thermal.thermal_resistance
    e, c0, c1 = _steps(t, tau)
    b = r * (c0 * p[:-1] + c1 * p[1:])
    theta = np.empty_like(p)
    theta[0] = 0.0
    for k in range(t.size - 1):
        theta[k + 1] = e[k] * theta[k] + b[k]
    beta = theta[-1]
    theta0 = math.exp(-duty.rest_time / tau) * beta / (-math.expm1(-duty.period / tau))
    theta = theta + theta0 * np.exp(-t / tau)
    j = int(np.argmax(theta))
    return WindingTemperature(
        temperature=thermal.ambient_temperature + theta,
        peak=float(thermal.ambient_temperature + theta[j]),
        peak_index=j,
        d_peak_d_loss=temperature_sensitivity(time, thermal, duty, j),
    )


def temperature_sensitivity(time: ArrayLike, thermal: ThermalParams, duty: Duty, index: int) -> Array:
    """Return d theta_index / d P_k [K/W] for every loss sample k, shape (K,) (exact: theta is linear in P)."""
    t, _ = _cycle_weights(time, duty)
    if not 0 <= index < t.size:
        raise InvalidInputError("index", index, f"must be in [0, {t.size - 1}]")
    tau, r = thermal.time_constant, thermal.thermal_resistance
    _, c0, c1 = _steps(t, tau)
    t_end = t[1:]  # b_k acts from t_{k+1} on
    # d theta_j / d b_k: direct path (k < j) plus the periodic initial value theta_0.
    wrap = math.exp(-duty.rest_time / tau) / (-math.expm1(-duty.period / tau))
    d_b = wrap * np.exp(-(t[-1] - t_end) / tau) * math.exp(-t[index] / tau)
    direct = np.arange(t.size - 1) < index
    d_b = d_b + np.where(direct, np.exp(-(t[index] - t_end) / tau), 0.0)
    grad = np.zeros_like(t)
    grad[:-1] += r * c0 * d_b
    grad[1:] += r * c1 * d_b
    return grad

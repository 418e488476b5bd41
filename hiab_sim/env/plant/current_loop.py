"""The drives' current loops in discrete time at the inverter's rate, with the inverter's dead time.

Per drive and PWM period T_s = 1 / f_s (f_s h periods per physics step, the speed omega_m held):

* sample: the measured currents i + offset + noise (:mod:`hiab_sim.env.plant.sensors`);
* PI with decoupling, K_p = L w_c, K_i = R_ref w_c (pole-zero cancellation on the nominal plant):
  x += K_i T_s e, v = K_p e + x + (-w_e L_q i_q, w_e (L_d i_d + Phi_PM)) with the measured currents;
  |v| > V_max scales v onto the inverter's circle and the integrator keeps its old value (anti-windup);
* apply: the voltage computed in period k is applied in period k + 1 (computation delay), minus the
  dead-time error (4/pi) t_d f_s V_dc i / sqrt(|i|^2 + i_eps^2) (the fundamental of each leg's
  error -t_d f_s V_dc sign(i_phase), i_eps = 1 A for the ripple that blurs the sign near zero);
* plant: eq. ``dq0voltage`` solved exactly for the held voltage, x(T) = E x0 + F u,
  int x = F x0 + G u with E = exp(A T), F = A^-1 (E - I), G = A^-1 (F - T I) (the 2x2 exponential
  of :func:`hiab_sim.emla.drive_sim.plant_step`), at T_s and T_s / 2.

Energies per period: electrical int 3/2 v.i dt exact for the held (applied) voltage; copper
3/2 R_s int |i|^2 dt and the torque by Simpson's rule (start, middle, end). The inverter's loss is
the EMLA file's (:func:`hiab_sim.emla.losses.inverter_loss`, charged by :mod:`hiab_sim.env.drive_losses`
as for the continuous loop): the step hands over |i_dq| at the start, middle and end of every period
with Simpson's weights, so the loss follows the current's ripple within the step. The plant holds no
inverter-loss data of its own (one loss model, the planner's). With a rising f_s the loop tends to
the continuous one of :mod:`hiab_sim.emla.drive_sim` (the tests check it).
"""

from __future__ import annotations

import cmath
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.emla.drive_sim import DriveArrays, DriveSimulator, DriveStep
from hiab_sim.env.plant.config import CurrentLoop
from hiab_sim.env.plant.sensors import CurrentSensorError
from hiab_sim.errors import InvalidInputError

Array = NDArray[np.float64]

#: Current scale [A] of the smooth sign of the dead-time error (model choice, see the module docstring).
DEAD_TIME_CURRENT_A = 1.0


def _exp_maps(a11: float, a12: float, a21: float, a22: float, t: float) -> tuple[tuple[float, ...], ...]:
    """E = exp(A t), F = A^-1 (E - I), G = A^-1 (F - t I) of a 2x2 A with det(A) != 0, row-major."""
    m = 0.5 * (a11 + a22)
    det = a11 * a22 - a12 * a21
    q = cmath.sqrt(m * m - det)
    if abs(q * t) < 1e-8:
        ch, sh = 1.0, t
    else:
        ch, sh = cmath.cosh(q * t).real, (cmath.sinh(q * t) / q).real
    g = math.exp(m * t)
    e = (g * (ch + sh * (a11 - m)), g * sh * a12, g * sh * a21, g * (ch + sh * (a22 - m)))
    inv = (a22 / det, -a12 / det, -a21 / det, a11 / det)

    def times_inv(x: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
        return (
            inv[0] * x[0] + inv[1] * x[2],
            inv[0] * x[1] + inv[1] * x[3],
            inv[2] * x[0] + inv[3] * x[2],
            inv[2] * x[1] + inv[3] * x[3],
        )

    f = times_inv((e[0] - 1.0, e[1], e[2], e[3] - 1.0))
    gg = times_inv((f[0] - t, f[1], f[2], f[3] - t))
    return e, f, gg


class DiscreteCurrentLoop(DriveSimulator):
    """n drives under discrete PI current loops at the inverter rate (module docstring).

    Args:
        drives: The plant's drive parameters (R_s may be hot: see :meth:`set_resistance`).
        loop: Rate, bandwidth, dead time and losses.
        sensor: Current-measurement errors (offset and noise per sample).
        h: Physics step [s]; f_s h must be an integer.

    """

    def __init__(self, drives: DriveArrays, loop: CurrentLoop, sensor: CurrentSensorError, h: float) -> None:
        super().__init__(drives, bandwidth_hz=loop.bandwidth_Hz)
        periods = loop.rate_Hz * h
        if abs(periods - round(periods)) > 1e-6 or round(periods) < 1:
            raise InvalidInputError(
                "current_loop.rate_Hz", loop.rate_Hz, f"must be a multiple of 1/h = {1 / h:g} Hz", "Hz"
            )
        self.loop = loop
        self.sensor = sensor
        self.periods = round(periods)
        self.period = h / self.periods
        self.nominal_resistance = drives.resistance.copy()
        self.x_d = np.zeros(len(drives.names))
        self.x_q = np.zeros(len(drives.names))
        self.pending_d = np.zeros(len(drives.names))
        self.pending_q = np.zeros(len(drives.names))
        # Simpson's weights of the nodes start, middle, end of every period (shared ends added up) [s].
        weights = np.zeros(2 * self.periods + 1)
        weights[0:-1:2] += self.period / 6.0
        weights[1::2] += 4.0 * self.period / 6.0
        weights[2::2] += self.period / 6.0
        self.sample_weights = weights

    def reset(self, i_d: ArrayLike, i_q: ArrayLike) -> None:
        """Set the currents; integrators and the pending voltage at the steady state at rest."""
        super().reset(i_d, i_q)
        self.x_d = self.nominal_resistance * self.i_d
        self.x_q = self.nominal_resistance * self.i_q
        self.pending_d = self.x_d.copy()
        self.pending_q = self.x_q.copy()

    def step(self, reference_q: ArrayLike, omega_m: ArrayLike, h: float) -> DriveStep:
        """Advance every drive by h [s] (``self.periods`` PWM periods) at held motor speeds [rad/s]."""
        d = self.drives
        omega = np.asarray(omega_m, dtype=float)
        requested = np.asarray(reference_q, dtype=float)
        limit = d.current_limit
        ref_q = np.minimum(np.maximum(requested, -limit), limit)
        errors = self.sensor.sample(self.periods)
        noise_d = self.sensor.sample(self.periods) - self.sensor.offset if self.sensor.enabled else errors
        n = len(d.names)
        out = {key: np.zeros(n) for key in ("id", "iq", "vd", "vq", "energy", "copper", "torque")}
        samples = np.zeros((n, 2 * self.periods + 1))
        saturated = np.zeros(n, dtype=bool)
        loop = self.loop
        T = self.period
        wc = self.bandwidth
        v_dead = loop.dead_time_voltage_V
        eps2 = DEAD_TIME_CURRENT_A**2
        for j in range(n):
            r, ld, lq, p, flux = (
                float(d.resistance[j]),
                float(d.Ld[j]),
                float(d.Lq[j]),
                float(d.pole_pairs[j]),
                float(d.flux[j]),
            )
            w_e = p * float(omega[j])
            a11, a12, a21, a22 = -r / ld, w_e * lq / ld, -w_e * ld / lq, -r / lq
            e1, f1, g1 = _exp_maps(a11, a12, a21, a22, T)
            e2, f2, _ = _exp_maps(a11, a12, a21, a22, 0.5 * T)
            kp_d, kp_q = ld * wc, lq * wc
            ki = float(self.nominal_resistance[j]) * wc * T
            vmax2 = float(d.voltage_limit[j]) ** 2
            i_d, i_q = float(self.i_d[j]), float(self.i_q[j])
            x_d, x_q = float(self.x_d[j]), float(self.x_q[j])
            pend_d, pend_q = float(self.pending_d[j]), float(self.pending_q[j])
            ref = float(ref_q[j])
            energy = copper = torque = 0.0
            row = samples[j]
            row[0] = math.hypot(i_d, i_q)
            sat = False
            va_d = va_q = 0.0
            for k in range(self.periods):
                m_d, m_q = i_d + float(noise_d[k, j]), i_q + float(errors[k, j])
                err_d, err_q = -m_d, ref - m_q
                nx_d, nx_q = x_d + ki * err_d, x_q + ki * err_q
                v_d = kp_d * err_d + nx_d - w_e * lq * m_q
                v_q = kp_q * err_q + nx_q + w_e * (ld * m_d + flux)
                norm2 = v_d * v_d + v_q * v_q
                if norm2 > vmax2:
                    scale = math.sqrt(vmax2 / norm2)
                    v_d, v_q = v_d * scale, v_q * scale
                    sat = True
                else:
                    x_d, x_q = nx_d, nx_q
                # Apply the previous period's command, less the dead-time error at this period's current.
                blur = v_dead / math.sqrt(i_d * i_d + i_q * i_q + eps2)
                va_d, va_q = pend_d - blur * i_d, pend_q - blur * i_q
                pend_d, pend_q = v_d, v_q
                u_d, u_q = va_d / ld, (va_q - w_e * flux) / lq
                end_d = e1[0] * i_d + e1[1] * i_q + f1[0] * u_d + f1[1] * u_q
                end_q = e1[2] * i_d + e1[3] * i_q + f1[2] * u_d + f1[3] * u_q
                mid_d = e2[0] * i_d + e2[1] * i_q + f2[0] * u_d + f2[1] * u_q
                mid_q = e2[2] * i_d + e2[3] * i_q + f2[2] * u_d + f2[3] * u_q
                int_d = f1[0] * i_d + f1[1] * i_q + g1[0] * u_d + g1[1] * u_q
                int_q = f1[2] * i_d + f1[3] * i_q + g1[2] * u_d + g1[3] * u_q
                energy += 1.5 * (va_d * int_d + va_q * int_q)
                s0, sm, s1 = i_d * i_d + i_q * i_q, mid_d * mid_d + mid_q * mid_q, end_d * end_d + end_q * end_q
                squares = T * (s0 + 4.0 * sm + s1) / 6.0
                copper += 1.5 * r * squares
                products = T * (i_d * i_q + 4.0 * mid_d * mid_q + end_d * end_q) / 6.0
                torque += 1.5 * p * (flux * int_q + (ld - lq) * products)
                row[2 * k + 1], row[2 * k + 2] = math.sqrt(sm), math.sqrt(s1)
                i_d, i_q = end_d, end_q
            self.x_d[j], self.x_q[j] = x_d, x_q
            self.pending_d[j], self.pending_q[j] = pend_d, pend_q
            out["id"][j], out["iq"][j], out["vd"][j], out["vq"][j] = i_d, i_q, va_d, va_q
            out["energy"][j], out["copper"][j], out["torque"][j] = energy, copper, torque / h
            saturated[j] = sat
        self.i_d, self.i_q = out["id"], out["iq"]
        friction = d.coulomb * np.tanh(omega / d.smoothing)
        return DriveStep(
            i_d=out["id"],
            i_q=out["iq"],
            v_d=out["vd"],
            v_q=out["vq"],
            electrical_energy=out["energy"],
            copper_energy=out["copper"],
            torque=out["torque"],
            friction_torque=friction,
            rod_force=d.ratio * (out["torque"] - friction),
            current_limited=np.abs(requested) >= limit,
            voltage_limited=saturated,
            current_samples=samples,
            sample_weights=self.sample_weights,
        )

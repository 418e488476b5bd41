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
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.emla.drive_sim import DriveArrays, DriveSimulator, DriveStep
from hiab_sim.env.plant.config import CurrentLoop
from hiab_sim.env.plant.sensors import CurrentSensorError
from hiab_sim.errors import InvalidInputError

#: A 2x2 matrix, row-major.
Quad = tuple[float, float, float, float]

#: Current scale [A] of the smooth sign of the dead-time error (model choice, see the module docstring).
DEAD_TIME_CURRENT_A = 1.0


def _exp_maps_full_half(
    a11: float, a12: float, a21: float, a22: float, t: float
) -> tuple[tuple[Quad, Quad, Quad], tuple[Quad, Quad]]:
    """((E, F, G) at t, (E, F) at t / 2) of a 2x2 A with det(A) != 0, row-major, sharing the eigenvalues and A^-1.

    E = exp(A t), F = A^-1 (E - I), G = A^-1 (F - t I).

    One evaluation per drive and physics step: the speed, and so A, is held over the step.
    """
    m = 0.5 * (a11 + a22)
    det = a11 * a22 - a12 * a21
    q = cmath.sqrt(m * m - det)
    i0, i1, i2, i3 = a22 / det, -a12 / det, -a21 / det, a11 / det
    maps = []
    for span in (t, 0.5 * t):
        if abs(q * span) < 1e-8:
            ch, sh = 1.0, span
        else:
            ch, sh = cmath.cosh(q * span).real, (cmath.sinh(q * span) / q).real
        g = math.exp(m * span)
        e0, e1, e2, e3 = g * (ch + sh * (a11 - m)), g * sh * a12, g * sh * a21, g * (ch + sh * (a22 - m))
        x0, x1, x2, x3 = e0 - 1.0, e1, e2, e3 - 1.0
        f0, f1, f2, f3 = i0 * x0 + i1 * x2, i0 * x1 + i1 * x3, i2 * x0 + i3 * x2, i2 * x1 + i3 * x3
        maps.append(((e0, e1, e2, e3), (f0, f1, f2, f3)))
    (e, f), half = maps
    x0, x1, x2, x3 = f[0] - t, f[1], f[2], f[3] - t
    gg = (i0 * x0 + i1 * x2, i0 * x1 + i1 * x3, i2 * x0 + i3 * x2, i2 * x1 + i3 * x3)
    return (e, f, gg), half


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
        self._cached: tuple[tuple[Array, ...], tuple[list[float], ...]] | None = None

    def reset(self, i_d: ArrayLike, i_q: ArrayLike) -> None:
        """Set the currents; integrators and the pending voltage at the steady state at rest."""
        super().reset(i_d, i_q)
        self.x_d = self.nominal_resistance * self.i_d
        self.x_q = self.nominal_resistance * self.i_q
        self.pending_d = self.x_d.copy()
        self.pending_q = self.x_q.copy()

    def step(self, reference_q: ArrayLike, omega_m: ArrayLike, h: float) -> DriveStep:
        """Advance every drive by h [s] (``self.periods`` PWM periods) at held motor speeds [rad/s].

        Scalar Python per drive and period (a few drives, eight periods: numpy's per-call cost on
        arrays of three would exceed the arithmetic); the constants are read once per parameter set.
        """
        d = self.drives
        omega = np.asarray(omega_m, dtype=float)
        requested = np.asarray(reference_q, dtype=float)
        limit = d.current_limit
        ref_q = np.minimum(np.maximum(requested, -limit), limit)
        errors = self.sensor.sample(self.periods)
        noise_d = self.sensor.sample(self.periods) - self.sensor.offset if self.sensor.enabled else errors
        n = len(d.names)
        ld_all, lq_all, p_all, flux_all, ki_all, vmax2_all = self._constants(d)
        r_all = d.resistance.tolist()
        omega_all, ref_all = omega.tolist(), ref_q.tolist()
        noise_q_all, noise_d_all = errors.T.tolist(), noise_d.T.tolist()
        state_id, state_iq = self.i_d.tolist(), self.i_q.tolist()
        state_xd, state_xq = self.x_d.tolist(), self.x_q.tolist()
        state_pd, state_pq = self.pending_d.tolist(), self.pending_q.tolist()
        out_id, out_iq, out_vd, out_vq, out_energy, out_copper, out_torque = ([0.0] * n for _ in range(7))
        samples = np.empty((n, 2 * self.periods + 1))
        saturated = np.zeros(n, dtype=bool)
        periods = range(self.periods)
        T = self.period
        wc = self.bandwidth
        v_dead = self.loop.dead_time_voltage_V
        eps2 = DEAD_TIME_CURRENT_A**2
        for j in range(n):
            r, ld, lq, p, flux = r_all[j], ld_all[j], lq_all[j], p_all[j], flux_all[j]
            w_e = p * omega_all[j]
            a11, a12, a21, a22 = -r / ld, w_e * lq / ld, -w_e * ld / lq, -r / lq
            (e1, f1, g1), (e2, f2) = _exp_maps_full_half(a11, a12, a21, a22, T)
            e10, e11, e12, e13 = e1
            f10, f11, f12, f13 = f1
            g10, g11, g12, g13 = g1
            e20, e21, e22, e23 = e2
            f20, f21, f22, f23 = f2
            kp_d, kp_q = ld * wc, lq * wc
            ki = ki_all[j]
            vmax2 = vmax2_all[j]
            i_d, i_q = state_id[j], state_iq[j]
            x_d, x_q = state_xd[j], state_xq[j]
            pend_d, pend_q = state_pd[j], state_pq[j]
            ref = ref_all[j]
            noise_q, noise_dj = noise_q_all[j], noise_d_all[j]
            energy = copper = torque = 0.0
            row = [math.hypot(i_d, i_q)]
            sat = False
            va_d = va_q = 0.0
            for k in periods:
                m_d, m_q = i_d + noise_dj[k], i_q + noise_q[k]
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
                end_d = e10 * i_d + e11 * i_q + f10 * u_d + f11 * u_q
                end_q = e12 * i_d + e13 * i_q + f12 * u_d + f13 * u_q
                mid_d = e20 * i_d + e21 * i_q + f20 * u_d + f21 * u_q
                mid_q = e22 * i_d + e23 * i_q + f22 * u_d + f23 * u_q
                int_d = f10 * i_d + f11 * i_q + g10 * u_d + g11 * u_q
                int_q = f12 * i_d + f13 * i_q + g12 * u_d + g13 * u_q
                energy += 1.5 * (va_d * int_d + va_q * int_q)
                s0, sm, s1 = i_d * i_d + i_q * i_q, mid_d * mid_d + mid_q * mid_q, end_d * end_d + end_q * end_q
                squares = T * (s0 + 4.0 * sm + s1) / 6.0
                copper += 1.5 * r * squares
                products = T * (i_d * i_q + 4.0 * mid_d * mid_q + end_d * end_q) / 6.0
                torque += 1.5 * p * (flux * int_q + (ld - lq) * products)
                row.append(math.sqrt(sm))
                row.append(math.sqrt(s1))
                i_d, i_q = end_d, end_q
            state_xd[j], state_xq[j] = x_d, x_q
            state_pd[j], state_pq[j] = pend_d, pend_q
            out_id[j], out_iq[j], out_vd[j], out_vq[j] = i_d, i_q, va_d, va_q
            out_energy[j], out_copper[j], out_torque[j] = energy, copper, torque / h
            samples[j] = row
            saturated[j] = sat
        self.x_d, self.x_q = np.array(state_xd), np.array(state_xq)
        self.pending_d, self.pending_q = np.array(state_pd), np.array(state_pq)
        return self._end_step(
            omega,
            requested,
            i_d=np.array(out_id),
            i_q=np.array(out_iq),
            v_d=np.array(out_vd),
            v_q=np.array(out_vq),
            electrical_energy=np.array(out_energy),
            copper_energy=np.array(out_copper),
            torque=np.array(out_torque),
            voltage_limited=saturated,
            current_samples=samples,
            sample_weights=self.sample_weights,
        )

    def _constants(self, d: DriveArrays) -> tuple[list[float], ...]:
        """(L_d, L_q, p, Phi_PM, K_i T_s, V_max^2) per drive as floats, read again only when they change.

        R_s is not among them: the winding temperature hands over a new one every step.
        """
        key = (d.Ld, d.Lq, d.pole_pairs, d.flux, d.voltage_limit)
        cached = self._cached
        if cached is None or any(a is not b for a, b in zip(cached[0], key, strict=True)):
            ki = (self.nominal_resistance * self.bandwidth * self.period).tolist()
            vmax2 = [v**2 for v in d.voltage_limit.tolist()]
            values = (d.Ld.tolist(), d.Lq.tolist(), d.pole_pairs.tolist(), d.flux.tolist(), ki, vmax2)
            cached = self._cached = (key, values)
        return cached[1]

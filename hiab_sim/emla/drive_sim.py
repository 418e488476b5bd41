"""Time-domain simulation of the EMLA drives: dq current dynamics under a current controller, vectorised.

Plant (eq. ``dq0voltage``) per drive, with electrical speed w_e = p omega_m:

    L_d di_d/dt = v_d - R_s i_d + w_e L_q i_q
    L_q di_q/dt = v_q - R_s i_q - w_e (L_d i_d + Phi_PM)
    tau_m       = 3/2 p i_q (Phi_PM + (L_d - L_q) i_d)

Current controller. A drive's current loop runs at 8-16 kHz, far above the 1 kHz physics rate, so
it is modelled in continuous time: an internal-model (IMC) controller with the plant's own R_s, L,

    v_d = L_d w_c (i_d* - i_d) + R_s i_d - w_e L_q i_q
    v_q = L_q w_c (i_q* - i_q) + R_s i_q + w_e (L_d i_d + Phi_PM)

which is the PI controller with pole-zero cancellation (K_p = L w_c, K_i = R_s w_c) and decoupling,
without an integrator to wind up. Unsaturated, each axis follows di/dt = w_c (i* - i) exactly. The
inverter's limit is a circle: |v_dq| <= V_max = sqrt(2/3) V_LL,max (amplitude-invariant transform,
:func:`hiab_sim.emla.park.line_voltage_rms`); beyond it the command is scaled onto the circle,
keeping its direction, and the current then follows the plant under that voltage. Current
references are clipped to the drive's current limit I_max = tau_peak / (3/2 p Phi_PM).

Integration over one step of length h, with the speed omega_m held (it comes from the multibody step):

* unsaturated: i(t) = i* + (i0 - i*) s(t), s = exp(-w_c t), and v(t) is affine in s, so the
  electrical energy int 3/2 v.i dt, the copper loss int 3/2 R_s |i|^2 dt, the mean torque and the
  mean currents are closed-form integrals of 1, s and s^2. |v(t)|^2 is a convex quadratic in s, so
  checking the limit at both ends of the step is exact;
* saturated (any end of the step outside the circle): ``saturated_substeps`` sub-steps with the
  voltage held (zero-order hold), each solved exactly with the 2x2 matrix exponential of the plant;
  electrical energy is exact for the held voltage, copper loss and torque use Simpson's rule.

The rod force handed to the multibody model is f = k (tau_m - tau_f tanh(omega_m / omega_eps)),
k = 2 pi G / rho (eqs. ``torque_torque``, ``torque_force``): the rotor inertia J_m k^2 (plus M_sm) is
the slide's armature and the screw's viscous friction b_f its damping (:mod:`hiab_sim.model.mjcf`),
so the force on the load is f_x = f - (J_m k^2 + M_sm) a_x - b_f v_x, as in the paper.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaParams
from hiab_sim.errors import InvalidInputError


def _stack(params: tuple[EmlaParams, ...], getter: str) -> Array:
    """Array of the attribute path ``getter`` (e.g. ``motor.Ld``) of every EMLA."""
    values = []
    for param in params:
        value: object = param
        for part in getter.split("."):
            value = getattr(value, part)
        values.append(float(value))  # type: ignore[arg-type]
    return np.array(values)


@dataclass(frozen=True)
class DriveArrays:
    """Parameters of n drives as arrays of shape (n,), SI units (see :class:`~hiab_sim.emla.config.EmlaParams`)."""

    names: tuple[str, ...]
    resistance: Array  # R_s [ohm]
    Ld: Array  # [H]
    Lq: Array  # [H]
    pole_pairs: Array  # p [-]
    flux: Array  # Phi_PM [Wb]
    rotor_inertia: Array  # J_m [kg m^2]
    coulomb: Array  # tau_f [N m]
    smoothing: Array  # omega_eps [rad/s]
    ratio: Array  # k = 2 pi G / rho [rad/m]
    viscous: Array  # b_f [N s/m]
    screw_mass: Array  # M_sm [kg]
    voltage_limit: Array  # V_max = sqrt(2/3) V_LL,max, peak phase (|v_dq|) [V]
    current_limit: Array  # I_max = tau_peak / (3/2 p Phi_PM) [A]

    @classmethod
    def from_params(cls, emlas: Iterable[EmlaParams]) -> DriveArrays:
        """Stack the parameters of the given EMLAs (e.g. an :class:`~hiab_sim.emla.config.EmlaSet`)."""
        params = tuple(emlas)
        if not params:
            raise InvalidInputError("emlas", "empty", "must name at least one EMLA")
        kt = np.array([p.motor.torque_constant for p in params])
        return cls(
            names=tuple(p.name for p in params),
            resistance=_stack(params, "motor.stator_resistance"),
            Ld=_stack(params, "motor.Ld"),
            Lq=_stack(params, "motor.Lq"),
            pole_pairs=_stack(params, "motor.pole_pairs"),
            flux=_stack(params, "motor.flux_linkage"),
            rotor_inertia=_stack(params, "motor.rotor_inertia"),
            coulomb=_stack(params, "motor.rotor_coulomb_friction"),
            smoothing=_stack(params, "motor.friction_smoothing_speed"),
            ratio=np.array([p.transmission_ratio for p in params]),
            viscous=_stack(params, "viscous_friction"),
            screw_mass=_stack(params, "screw_moving_mass"),
            voltage_limit=np.sqrt(2.0 / 3.0) * _stack(params, "motor.max_line_voltage_rms"),
            current_limit=_stack(params, "motor.peak_torque") / kt,
        )

    @property
    def torque_constant(self) -> Array:
        """K_t = 3/2 p Phi_PM [N m/A]."""
        return 1.5 * self.pole_pairs * self.flux

    @property
    def reflected_inertia(self) -> Array:
        """Rotor and screw inertia seen at the rod, J_m k^2 + M_sm [kg] (eq. ``torque_torque`` x k)."""
        return self.rotor_inertia * self.ratio**2 + self.screw_mass

    def friction_torque(self, omega_m: Array) -> Array:
        """Regularised rotor Coulomb friction tau_f tanh(omega_m / omega_eps) [N m]."""
        return self.coulomb * np.tanh(omega_m / self.smoothing)

    def torque(self, i_d: Array, i_q: Array) -> Array:
        """Electromagnetic torque 3/2 p i_q (Phi_PM + (L_d - L_q) i_d) [N m] (eq. ``dq0voltage``)."""
        return 1.5 * self.pole_pairs * i_q * (self.flux + (self.Ld - self.Lq) * i_d)

    def magnetic_energy(self, i_d: Array, i_q: Array) -> Array:
        """Energy stored in the stator inductances, 3/4 (L_d i_d^2 + L_q i_q^2) [J]."""
        return 0.75 * (self.Ld * i_d**2 + self.Lq * i_q**2)


@dataclass(frozen=True)
class DriveStep:
    """Result of one step of n drives; arrays (n,).

    Attributes:
        i_d, i_q: Currents at the end of the step [A].
        v_d, v_q: Voltages applied at the end of the step [V].
        electrical_energy: int 3/2 (v_d i_d + v_q i_q) dt over the step [J].
        copper_energy: int 3/2 R_s (i_d^2 + i_q^2) dt [J].
        torque: Mean electromagnetic torque over the step [N m].
        friction_torque: Rotor Coulomb friction at the step's speed [N m].
        rod_force: k (torque - friction_torque) [N], the force handed to the slide.
        current_limited: The reference was clipped to the current limit.
        voltage_limited: The voltage command left the inverter's circle during the step.
        inverter_energy: The inverter's loss over the step [J] (0 here: the EMLA file's inverter loss is
            charged from the current samples by :mod:`hiab_sim.env.drive_losses`).
        current_samples: |i_dq| [A] per drive at the step's quadrature nodes, (n, m), or None.
        sample_weights: The nodes' quadrature weights [s], (m,), summing to the step: int g(|i|) dt over
            the step is about ``sample_weights @ g(current_samples[j])``.

    """

    i_d: Array
    i_q: Array
    v_d: Array
    v_q: Array
    electrical_energy: Array
    copper_energy: Array
    torque: Array
    friction_torque: Array
    rod_force: Array
    current_limited: NDArray[np.bool_]
    voltage_limited: NDArray[np.bool_]
    inverter_energy: Array | float = 0.0
    current_samples: Array | None = None
    sample_weights: Array | None = None


class DriveSimulator:
    """n EMLA drives under their current controllers; state: the dq currents.

    Args:
        drives: Drive parameters.
        bandwidth_hz: Current-loop bandwidth w_c / 2 pi [Hz].
        saturated_substeps: Sub-steps of a step in which the voltage limit engages.

    """

    def __init__(self, drives: DriveArrays, bandwidth_hz: float = 500.0, saturated_substeps: int = 20) -> None:
        if not (math.isfinite(bandwidth_hz) and bandwidth_hz > 0):
            raise InvalidInputError("bandwidth_hz", bandwidth_hz, "must be finite and > 0", "Hz")
        if isinstance(saturated_substeps, bool) or not isinstance(saturated_substeps, int) or saturated_substeps < 2:
            raise InvalidInputError("saturated_substeps", saturated_substeps, "must be an integer >= 2")
        self.drives = drives
        self.bandwidth = 2.0 * math.pi * bandwidth_hz
        self.saturated_substeps = saturated_substeps
        n = len(drives.names)
        self.i_d = np.zeros(n)
        self.i_q = np.zeros(n)

    def reset(self, i_d: ArrayLike, i_q: ArrayLike) -> None:
        """Set the dq currents [A]."""
        self.i_d = np.array(i_d, dtype=float) * np.ones_like(self.i_d)
        self.i_q = np.array(i_q, dtype=float) * np.ones_like(self.i_q)

    def command(self, i_d: Array, i_q: Array, ref_d: Array, ref_q: Array, omega_m: Array) -> tuple[Array, Array]:
        """Unsaturated controller voltages (v_d, v_q) [V] for currents, references and speed."""
        d = self.drives
        w_e = d.pole_pairs * omega_m
        v_d = d.Ld * self.bandwidth * (ref_d - i_d) + d.resistance * i_d - w_e * d.Lq * i_q
        v_q = d.Lq * self.bandwidth * (ref_q - i_q) + d.resistance * i_q + w_e * (d.Ld * i_d + d.flux)
        return v_d, v_q

    def step(self, reference_q: ArrayLike, omega_m: ArrayLike, h: float) -> DriveStep:
        """Advance every drive by h [s] with q-current references [A] (i_d* = 0) at motor speeds [rad/s]."""
        d = self.drives
        omega = np.asarray(omega_m, dtype=float)
        requested = np.asarray(reference_q, dtype=float)
        limit = d.current_limit
        ref_q = np.minimum(np.maximum(requested, -limit), limit)
        i_d0, i_q0 = self.i_d, self.i_q
        e_d, e_q = i_d0, i_q0 - ref_q  # errors to the references (i_d* = 0)

        # Unsaturated: i = i* + e s and v = a + b s with s = exp(-w_c t) (module docstring).
        wc = self.bandwidth
        s = math.exp(-wc * h)
        s1 = (1.0 - s) / wc  # int_0^h s dt
        s2 = (1.0 - s * s) / (2.0 * wc)  # int_0^h s^2 dt
        w_e = d.pole_pairs * omega
        r = d.resistance
        lq_w = w_e * d.Lq
        a_d = -lq_w * ref_q
        b_d = (r - d.Ld * wc) * e_d - lq_w * e_q
        a_q = r * ref_q + w_e * d.flux
        b_q = (r - d.Lq * wc) * e_q + w_e * d.Ld * e_d
        v_d, v_q = a_d + b_d * s, a_q + b_q * s
        v_d0, v_q0 = a_d + b_d, a_q + b_q
        limit2 = d.voltage_limit**2
        saturated = (v_d0 * v_d0 + v_q0 * v_q0 > limit2) | (v_d * v_d + v_q * v_q > limit2)
        energy = 1.5 * (a_q * ref_q * h + (a_d * e_d + a_q * e_q + b_q * ref_q) * s1 + (b_d * e_d + b_q * e_q) * s2)
        copper = 1.5 * r * (ref_q * ref_q * h + 2.0 * ref_q * e_q * s1 + (e_d * e_d + e_q * e_q) * s2)
        mean_q = ref_q * h + e_q * s1
        mean_dq = ref_q * e_d * s1 + e_d * e_q * s2
        torque = 1.5 * d.pole_pairs * (d.flux * mean_q + (d.Ld - d.Lq) * mean_dq) / h
        i_d1, i_q1 = e_d * s, ref_q + e_q * s
        root = math.sqrt(s)  # exp(-w_c h / 2): the unsaturated current at mid-step
        i_dm, i_qm = e_d * root, ref_q + e_q * root

        if saturated.any():
            sat = self._saturated(i_d0, i_q0, np.zeros_like(ref_q), ref_q, omega, h)
            i_d1 = np.where(saturated, sat[0], i_d1)
            i_q1 = np.where(saturated, sat[1], i_q1)
            v_d = np.where(saturated, sat[2], v_d)
            v_q = np.where(saturated, sat[3], v_q)
            energy = np.where(saturated, sat[4], energy)
            copper = np.where(saturated, sat[5], copper)
            torque = np.where(saturated, sat[6], torque)
            i_dm = np.where(saturated, 0.5 * (i_d0 + i_d1), i_dm)  # the sub-stepped path: the chord's middle
            i_qm = np.where(saturated, 0.5 * (i_q0 + i_q1), i_qm)

        samples = np.stack([np.hypot(i_d0, i_q0), np.hypot(i_dm, i_qm), np.hypot(i_d1, i_q1)], axis=1)
        return self._end_step(
            omega,
            requested,
            i_d=i_d1,
            i_q=i_q1,
            v_d=v_d,
            v_q=v_q,
            electrical_energy=energy,
            copper_energy=copper,
            torque=torque,
            voltage_limited=saturated,
            current_samples=samples,
            sample_weights=np.array([h / 6.0, 4.0 * h / 6.0, h / 6.0]),  # Simpson's rule
        )

    def _end_step(
        self,
        omega_m: Array,
        requested: Array,
        *,
        i_d: Array,
        i_q: Array,
        v_d: Array,
        v_q: Array,
        electrical_energy: Array,
        copper_energy: Array,
        torque: Array,
        voltage_limited: NDArray[np.bool_],
        current_samples: Array,
        sample_weights: Array,
    ) -> DriveStep:
        """Keep a step's end currents i_d, i_q [A] as the state and return the step (:class:`DriveStep`).

        The mechanical side is the same for every current loop: the rotor's Coulomb friction at the
        held motor speeds ``omega_m`` [rad/s], the rod force k (torque - friction) [N], and whether the
        requested q-currents ``requested`` [A] were clipped to the current limit.
        """
        self.i_d, self.i_q = i_d, i_q
        d = self.drives
        friction = d.friction_torque(omega_m)
        return DriveStep(
            i_d=i_d,
            i_q=i_q,
            v_d=v_d,
            v_q=v_q,
            electrical_energy=electrical_energy,
            copper_energy=copper_energy,
            torque=torque,
            friction_torque=friction,
            rod_force=d.ratio * (torque - friction),
            current_limited=np.abs(requested) >= d.current_limit,
            voltage_limited=voltage_limited,
            current_samples=current_samples,
            sample_weights=sample_weights,
        )

    def limited_command(
        self, i_d: Array, i_q: Array, ref_d: Array, ref_q: Array, omega_m: Array
    ) -> tuple[Array, Array]:
        """Controller voltages scaled onto the inverter's circle |v_dq| <= V_max where they leave it."""
        v_d, v_q = self.command(i_d, i_q, ref_d, ref_q, omega_m)
        norm = np.sqrt(v_d**2 + v_q**2)
        scale = np.minimum(1.0, self.drives.voltage_limit / np.maximum(norm, 1e-300))
        return v_d * scale, v_q * scale

    def _saturated(
        self, i_d: Array, i_q: Array, ref_d: Array, ref_q: Array, omega: Array, h: float
    ) -> tuple[Array, Array, Array, Array, Array, Array, Array]:
        """Sub-stepped zero-order-hold solution with the limited voltage (module docstring)."""
        d = self.drives
        dt = h / self.saturated_substeps
        energy = np.zeros_like(i_d)
        copper = np.zeros_like(i_d)
        torque = np.zeros_like(i_d)
        v_d = v_q = np.zeros_like(i_d)
        for _ in range(self.saturated_substeps):
            v_d, v_q = self.limited_command(i_d, i_q, ref_d, ref_q, omega)
            mid = plant_step(d, i_d, i_q, v_d, v_q, omega, 0.5 * dt)
            end = plant_step(d, i_d, i_q, v_d, v_q, omega, dt)
            energy = energy + 1.5 * (v_d * end[2] + v_q * end[3])
            sq0, sqm, sq1 = i_d**2 + i_q**2, mid[0] ** 2 + mid[1] ** 2, end[0] ** 2 + end[1] ** 2
            copper = copper + 1.5 * d.resistance * dt * (sq0 + 4.0 * sqm + sq1) / 6.0
            t0, tm, t1 = d.torque(i_d, i_q), d.torque(mid[0], mid[1]), d.torque(end[0], end[1])
            torque = torque + dt * (t0 + 4.0 * tm + t1) / 6.0
            i_d, i_q = end[0], end[1]
        return i_d, i_q, v_d, v_q, energy, copper, torque / h


def plant_step(
    drives: DriveArrays, i_d: Array, i_q: Array, v_d: Array, v_q: Array, omega_m: Array, dt: float
) -> tuple[Array, Array, Array, Array]:
    """Exact solution of eq. ``dq0voltage`` over dt [s] with voltages and speed held.

    dx/dt = A x + b, x = (i_d, i_q), A = [[-R/L_d, w_e L_q/L_d], [-w_e L_d/L_q, -R/L_q]],
    b = (v_d / L_d, (v_q - w_e Phi) / L_q). With m = tr(A)/2 and q^2 = m^2 - det(A),
    exp(A dt) = e^{m dt} (cosh(q dt) I + sinh(q dt)/q (A - m I)) (q may be imaginary).

    Returns:
        (i_d, i_q) at dt and (int i_d, int i_q) over [0, dt] [A s].

    """
    w_e = drives.pole_pairs * omega_m
    r = drives.resistance
    a11, a12 = -r / drives.Ld, w_e * drives.Lq / drives.Ld
    a21, a22 = -w_e * drives.Ld / drives.Lq, -r / drives.Lq
    b1, b2 = v_d / drives.Ld, (v_q - w_e * drives.flux) / drives.Lq
    det = a11 * a22 - a12 * a21
    # Steady state x_ss = -A^-1 b.
    xs1 = -(a22 * b1 - a12 * b2) / det
    xs2 = -(-a21 * b1 + a11 * b2) / det
    m = 0.5 * (a11 + a22)
    q = np.sqrt((m * m - det).astype(complex))
    small = np.abs(q * dt) < 1e-8
    q_safe = np.where(small, 1.0, q)
    ch = np.where(small, 1.0, np.cosh(q * dt)).real
    sh = np.where(small, dt, np.sinh(q * dt) / q_safe).real
    g = np.exp(m * dt)
    y1, y2 = i_d - xs1, i_q - xs2
    e11, e12 = g * (ch + sh * (a11 - m)), g * sh * a12
    e21, e22 = g * sh * a21, g * (ch + sh * (a22 - m))
    x1 = xs1 + e11 * y1 + e12 * y2
    x2 = xs2 + e21 * y1 + e22 * y2
    # int x dt = x_ss dt + A^-1 (x(dt) - x0) (because dy/dt = A y with y = x - x_ss).
    dy1, dy2 = x1 - i_d, x2 - i_q
    int1 = xs1 * dt + (a22 * dy1 - a12 * dy2) / det
    int2 = xs2 * dt + (-a21 * dy1 + a11 * dy2) / det
    return x1, x2, int1, int2

"""Load side to motor side: speed, torque, dq currents and voltages of one EMLA, with partials.

The chain of eqs. ``torque_force``, ``torque_torque`` and ``dq0voltage`` in steady electrical
state (di_d/dt = di_q/dt = 0; the magnetic energy 3/4 L i^2 is not tracked) and with zero-d-axis
current control (i_d = 0, the usual choice for a surface PMSM; with Ld != Lq the reluctance torque
is then unused, but V_d still uses L_q). Every quantity is vectorised over samples and comes with
its analytic partial derivatives with respect to load force f_x, velocity v_x and acceleration a_x.

Rotor Coulomb friction opposes the motor speed and is regularised as
tau_f tanh(omega_m / omega_eps) (omega_eps = ``friction_smoothing_speed``), so it is smooth and
exactly zero at standstill; its power tau_f tanh(omega_m / omega_eps) omega_m is never negative.

The optional direction-dependent transmission efficiency (:mod:`hiab_sim.emla.losses`, off by
default, then exactly 0) adds its loss torque tau_tr to the motor torque.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.losses import transmission_loss_torque

#: Partial derivatives (d/d f_x, d/d v_x, d/d a_x) of one quantity.
Partials = tuple[Array, Array, Array]


@dataclass(frozen=True)
class DriveState:
    """Motor-side state of one EMLA for load-side (f_x, v_x, a_x) samples; arrays of one shape.

    Attributes:
        motor_speed: omega_m = 2 pi G v_x / rho [rad/s].
        motor_acceleration: domega_m/dt = 2 pi G a_x / rho [rad/s^2].
        screw_force: f_sm = f_x + M_sm a_x + b_f v_x [N] (eq. ``torque_force``).
        screw_torque: tau_sm = rho f_sm / (2 pi G) [N m] (eq. ``torque_force``).
        friction_torque: tau_f tanh(omega_m / omega_eps) [N m].
        transmission_loss_torque: tau_tr [N m] of the optional transmission efficiency (0 when off).
        motor_torque: tau_m = tau_sm + tau_tr + J_m domega_m/dt + friction [N m] (eq. ``torque_torque``).
        i_d: d-axis current [A] (0).
        i_q: q-axis current tau_m / (3/2 p Phi_PM) [A].
        v_d: d-axis voltage -p omega_m L_q i_q [V].
        v_q: q-axis voltage R_s i_q + p omega_m Phi_PM [V].
        d_motor_speed: Partials of omega_m [rad/s per N, per m/s, per m/s^2].
        d_motor_torque: Partials of tau_m.
        d_i_q: Partials of i_q.
        d_v_d: Partials of v_d.
        d_v_q: Partials of v_q.

    """

    motor_speed: Array
    motor_acceleration: Array
    screw_force: Array
    screw_torque: Array
    friction_torque: Array
    transmission_loss_torque: Array
    motor_torque: Array
    i_d: Array
    i_q: Array
    v_d: Array
    v_q: Array
    d_motor_speed: Partials
    d_motor_torque: Partials
    d_i_q: Partials
    d_v_d: Partials
    d_v_q: Partials


def broadcast_inputs(force: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike) -> tuple[Array, Array, Array]:
    """Return force [N], velocity [m/s] and acceleration [m/s^2] as float arrays of one shape."""
    f, v, a = np.broadcast_arrays(
        np.asarray(force, dtype=float),
        np.asarray(velocity, dtype=float),
        np.asarray(acceleration, dtype=float),
    )
    return f, v, a


def drive_state(
    params: EmlaParams, force: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike, exact: bool = False
) -> DriveState:
    """Map load-side force [N], velocity [m/s] and acceleration [m/s^2] to the motor and its dq quantities.

    Args:
        params: The actuator.
        force: Load force f_x [N], positive when the actuator pushes.
        velocity: Rod velocity v_x [m/s], positive when extending.
        acceleration: Rod acceleration dv_x/dt [m/s^2].
        exact: Exact (kinked) transmission loss instead of its smooth form (no effect when it is off).

    """
    f, v, a = broadcast_inputs(force, velocity, acceleration)
    motor = params.motor
    k = params.transmission_ratio
    zeros = np.zeros_like(f)
    ones = np.ones_like(f)

    omega = k * v
    domega = k * a
    f_sm = f + params.screw_moving_mass * a + params.viscous_friction * v
    tau_sm = f_sm / k
    x = omega / motor.friction_smoothing_speed
    tau_fric = motor.rotor_coulomb_friction * np.tanh(x)
    tau_tr, dtr_df, dtr_dw = transmission_loss_torque(
        params.losses, f_sm, omega, k, motor.friction_smoothing_speed, exact
    )
    tau_m = tau_sm + motor.rotor_inertia * domega + tau_fric + tau_tr

    sech2 = 1.0 / np.cosh(np.clip(x, -350.0, 350.0)) ** 2
    d_omega: Partials = (zeros, k * ones, zeros)
    d_tau: Partials = (
        ones / k + dtr_df,
        params.viscous_friction / k
        + motor.rotor_coulomb_friction * sech2 * k / motor.friction_smoothing_speed
        + dtr_df * params.viscous_friction
        + dtr_dw * k,
        (params.screw_moving_mass / k + motor.rotor_inertia * k) * ones + dtr_df * params.screw_moving_mass,
    )

    kt = motor.torque_constant
    i_q = tau_m / kt
    i_d = np.zeros_like(f)
    d_iq: Partials = (d_tau[0] / kt, d_tau[1] / kt, d_tau[2] / kt)

    p = motor.pole_pairs
    r = motor.stator_resistance
    v_d = -p * omega * motor.Lq * i_q
    v_q = r * i_q + p * omega * motor.flux_linkage
    d_vd = tuple(-p * motor.Lq * (dw * i_q + omega * di) for dw, di in zip(d_omega, d_iq, strict=True))
    d_vq = tuple(r * di + p * motor.flux_linkage * dw for dw, di in zip(d_omega, d_iq, strict=True))

    return DriveState(
        motor_speed=omega,
        motor_acceleration=domega,
        screw_force=f_sm,
        screw_torque=tau_sm,
        friction_torque=tau_fric,
        transmission_loss_torque=tau_tr,
        motor_torque=tau_m,
        i_d=i_d,
        i_q=i_q,
        v_d=v_d,
        v_q=v_q,
        d_motor_speed=d_omega,
        d_motor_torque=d_tau,
        d_i_q=d_iq,
        d_v_d=(d_vd[0], d_vd[1], d_vd[2]),
        d_v_q=(d_vq[0], d_vq[1], d_vq[2]),
    )

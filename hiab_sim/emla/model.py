"""EMLA operating point: electrical power, loss breakdown, efficiency, gradients and energy.

Electrical power is computed on the electrical side, P_elec = 3/2 (V_d i_d + V_q i_q) (the dq form
of sqrt(3) V_LL I_LL cos(phi) in eq. ``system_efficiency``), never as f_x v_x / eta. It obeys

    P_elec = f_x v_x + P_copper + P_rotor_friction + P_screw_viscous + P_inertial

with P_copper = 3/2 R_s (i_d^2 + i_q^2), P_rotor_friction = tau_f tanh(omega_m/omega_eps) omega_m >= 0,
P_screw_viscous = b_f v_x^2 and P_inertial = (M_sm + J_m (2 pi G / rho)^2) a_x v_x (the rate of
change of the kinetic energy stored in screw and rotor, negative while decelerating).
When the load drives the actuator (f_x v_x < 0) the same equations give regeneration: P_elec < 0
as soon as the returned mechanical power exceeds the losses. No other sign convention is applied.

Optional drive losses (:mod:`hiab_sim.emla.losses`, all off by default, and then exactly the model
above): a transmission loss P_transmission = tau_tr omega_m in the motor torque, the inverter loss
P_inverter on the DC side, and a holding brake with release factor s (1 moving, 0 held):

    P_elec = s (P_motor + P_coil) + P_inverter(s i_q)
           = f_x v_x + s (P_copper + P_rotor_friction + P_screw_viscous + P_inertial + P_transmission)
             + s P_coil + P_inverter + P_brake_held,     P_brake_held = -(1 - s) f_x v_x,

with P_motor = 3/2 (V_d i_d + V_q i_q) at the motor terminals. ``exact=False`` (the solver's) uses
the smooth forms, ``exact=True`` (reports) the kinked and switched ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.drive import DriveState, drive_state
from hiab_sim.emla.envelope import margins_from_state
from hiab_sim.emla.losses import brake_release, inverter_loss
from hiab_sim.errors import InvalidInputError
from hiab_sim.quadrature import trapezoid


@dataclass(frozen=True)
class OperatingPoint:
    """Everything the EMLA model says about load-side samples (f_x, v_x, a_x); arrays of one shape.

    Attributes:
        motor_speed: omega_m [rad/s].
        motor_torque: tau_m [N m].
        i_d: d-axis current [A] (0, zero-d-axis-current control).
        i_q: q-axis current [A].
        v_d: d-axis voltage [V].
        v_q: q-axis voltage [V].
        line_voltage_rms: sqrt(3/2 (v_d^2 + v_q^2)) [V].
        electrical_power: P_elec [W], negative while regenerating (DC side when the inverter loss is on).
        mechanical_power: f_x v_x [W], delivered to the load.
        copper_loss: s 3/2 R_s (i_d^2 + i_q^2) [W].
        rotor_friction_loss: s tau_f tanh(omega_m/omega_eps) omega_m [W].
        screw_viscous_loss: s b_f v_x^2 [W].
        inertial_power: s (M_sm + J_m k^2) a_x v_x [W], k = 2 pi G / rho.
        transmission_loss: s tau_tr omega_m [W] (0 when the option is off).
        inverter_loss: P_inverter [W] (0 when off).
        brake_coil_power: s P_coil [W] (0 when off).
        brake_held_power: -(1 - s) f_x v_x [W], load power carried by the engaged brake (0 when off).
        brake_release: s [-], 1 where the motor carries the load (always 1 without a brake).
        efficiency: See :func:`efficiency`; NaN where undefined.
        margins: Envelope margins, shape ``(3,) + shape`` (see :mod:`hiab_sim.emla.envelope`).
        within_envelope: True where every margin is >= 0.

    """

    motor_speed: Array
    motor_torque: Array
    i_d: Array
    i_q: Array
    v_d: Array
    v_q: Array
    line_voltage_rms: Array
    electrical_power: Array
    mechanical_power: Array
    copper_loss: Array
    rotor_friction_loss: Array
    screw_viscous_loss: Array
    inertial_power: Array
    transmission_loss: Array
    inverter_loss: Array
    brake_coil_power: Array
    brake_held_power: Array
    brake_release: Array
    efficiency: Array
    margins: Array
    within_envelope: NDArray[np.bool_]


def operating_point(
    params: EmlaParams, force: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike, exact: bool = False
) -> OperatingPoint:
    """Evaluate the EMLA model at load force [N], rod velocity [m/s] and acceleration [m/s^2].

    Inputs broadcast to one shape. Eqs. ``torque_force``, ``torque_torque``, ``dq0voltage``,
    ``system_efficiency``; ``exact`` selects the exact forms of the optional drive losses.
    """
    s = drive_state(params, force, velocity, acceleration, exact)
    f, v, a = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (force, velocity, acceleration)))
    motor = params.motor
    p_elec, release, p_inv = _power(params, s, v, exact)
    p_mech = f * v
    margins = margins_from_state(params, s)
    return OperatingPoint(
        motor_speed=s.motor_speed,
        motor_torque=s.motor_torque,
        i_d=s.i_d,
        i_q=s.i_q,
        v_d=s.v_d,
        v_q=s.v_q,
        line_voltage_rms=np.sqrt(1.5 * (s.v_d**2 + s.v_q**2)),
        electrical_power=p_elec,
        mechanical_power=p_mech,
        copper_loss=release * 1.5 * motor.stator_resistance * (s.i_d**2 + s.i_q**2),
        rotor_friction_loss=release * s.friction_torque * s.motor_speed,
        screw_viscous_loss=release * params.viscous_friction * v * v,
        inertial_power=release
        * (params.screw_moving_mass + motor.rotor_inertia * params.transmission_ratio**2)
        * a
        * v,
        transmission_loss=release * s.transmission_loss_torque * s.motor_speed,
        inverter_loss=p_inv,
        brake_coil_power=release * params.losses.brake_coil_power,
        brake_held_power=-(1.0 - release) * p_mech,
        brake_release=release,
        efficiency=efficiency(p_mech, p_elec),
        margins=margins,
        within_envelope=np.all(margins >= 0.0, axis=0),
    )


def _power(params: EmlaParams, s: DriveState, v: Array, exact: bool) -> tuple[Array, Array, Array]:
    """Return (P_elec, s, P_inverter) [W, -, W] from a drive state (see the module docstring)."""
    release, _ = brake_release(params.losses, v, exact)
    p_motor = 1.5 * (s.v_d * s.i_d + s.v_q * s.i_q)
    p_inv, _ = inverter_loss(params.losses, release * s.i_q, exact)
    return np.asarray(release * (p_motor + params.losses.brake_coil_power) + p_inv), release, p_inv


def electrical_power(
    params: EmlaParams, force: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike, exact: bool = False
) -> Array:
    """Return P_elec [W] at load force [N], velocity [m/s], acceleration [m/s^2].

    With the drive-loss options off this is 3/2 (V_d i_d + V_q i_q), which replaces f_x v_x / eta_EMLA
    in the seed's cost (eq. ``costf2``): equal where eta is defined, finite where it is not (holding
    a load at v_x = 0 costs copper losses unless a holding brake is modelled).
    """
    s = drive_state(params, force, velocity, acceleration, exact)
    v = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (force, velocity, acceleration)))[1]
    return state_power(params, s, v, exact)


def state_power(params: EmlaParams, state: DriveState, velocity: Array, exact: bool = False) -> Array:
    """P_elec [W] of :func:`electrical_power` from the drive state at these samples (computed with ``exact``)."""
    return _power(params, state, velocity, exact)[0]


def electrical_power_partials(
    params: EmlaParams, force: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> tuple[Array, Array, Array]:
    """Return the analytic partials (dP/df_x [m/s], dP/dv_x [N], dP/da_x [kg m/s]) of the smooth P_elec.

    With i_d = 0, P_motor = 3/2 V_q i_q, so dP_motor = 3/2 (dV_q i_q + V_q di_q); the brake factor
    s(v_x) and the inverter loss P_inverter(s i_q) add their chain-rule terms (zero when off).
    """
    s = drive_state(params, force, velocity, acceleration)
    v = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (force, velocity, acceleration)))[1]
    return state_power_partials(params, s, v)


def state_power_partials(params: EmlaParams, s: DriveState, v: Array) -> tuple[Array, Array, Array]:
    """The partials of :func:`electrical_power_partials` from the smooth model's drive state at these samples."""
    losses = params.losses
    release, d_release = brake_release(losses, v, exact=False)
    p_motor = 1.5 * (s.v_d * s.i_d + s.v_q * s.i_q)
    _, d_inv = inverter_loss(losses, release * s.i_q, exact=False)
    d = []
    for j, (dvq, diq) in enumerate(zip(s.d_v_q, s.d_i_q, strict=True)):
        dp_motor = 1.5 * (dvq * s.i_q + s.v_q * diq)
        d_rel = d_release if j == 1 else 0.0
        d.append(
            release * dp_motor + d_rel * (p_motor + losses.brake_coil_power) + d_inv * (d_rel * s.i_q + release * diq)
        )
    return d[0], d[1], d[2]


def efficiency(mechanical_power: ArrayLike, electrical_power: ArrayLike) -> Array:
    """Return the EMLA efficiency for maps and reports (eq. ``system_efficiency``), NaN where undefined.

    * Motoring (f_x v_x > 0 and P_elec > 0): eta = f_x v_x / P_elec.
    * Generating (f_x v_x < 0): eta = P_elec / (f_x v_x), the fraction of the mechanical power the
      load returns that reaches the electrical side (= |P_elec| / |f_x v_x| while P_elec < 0). It
      is negative where the losses exceed the returned power and the drive still draws power.
    * NaN where f_x v_x = 0, or f_x v_x > 0 with P_elec <= 0 (only possible while the stored
      kinetic energy is released, a_x v_x < 0).

    eta <= 1 in every quadrant wherever a_x v_x >= 0, because P_elec - f_x v_x is then a sum of
    non-negative losses; while decelerating the released kinetic energy can make eta exceed 1.

    Args:
        mechanical_power: f_x v_x [W].
        electrical_power: P_elec [W].

    """
    pm, pe = np.broadcast_arrays(np.asarray(mechanical_power, dtype=float), np.asarray(electrical_power, dtype=float))
    eta = np.full(pm.shape, np.nan)
    motoring = (pm > 0) & (pe > 0)
    generating = pm < 0
    eta[motoring] = pm[motoring] / pe[motoring]
    eta[generating] = pe[generating] / pm[generating]
    return eta


def energy_summary(time: ArrayLike, electrical_power: ArrayLike) -> tuple[Array, Array]:
    """Return (net energy, drawn energy) [J] of a power history by the trapezoid rule.

    Net energy integrates P_elec (regeneration credited); drawn energy integrates max(P_elec, 0)
    sample by sample, i.e. the energy taken from the supply if nothing regenerated can be stored.
    The trapezoid rule on the clipped samples does not locate zero crossings; refine the grid if
    that matters.

    Args:
        time: Strictly increasing sample times [s], shape ``(n,)``, n >= 2.
        electrical_power: P_elec [W], shape ``(..., n)`` (time on the last axis).

    Returns:
        Two arrays of shape ``(...)`` (0-d for a single history).

    """
    t = np.asarray(time, dtype=float)
    p = np.asarray(electrical_power, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise InvalidInputError("time", f"shape {t.shape}", "must be one-dimensional with at least 2 samples")
    if not np.all(np.diff(t) > 0):
        raise InvalidInputError("time", "not increasing", "must be strictly increasing")
    if p.shape[-1:] != t.shape:
        raise InvalidInputError("electrical_power", f"shape {p.shape}", f"last axis must match time's {t.size} samples")
    return trapezoid(p, t), trapezoid(np.maximum(p, 0.0), t)


def peak_force(params: EmlaParams) -> float:
    """Return the largest push force [N]: 2 pi G eta_fwd (tau_peak - tau_f) / rho.

    The force at the peak motor torque while starting to move against the rotor's Coulomb friction
    (at a_x = 0 and v_x -> 0, so the viscous term vanishes), through the forward transmission
    efficiency eta_fwd (1 unless the drive-loss option is on). The regularised friction and the
    smooth transmission loss are zero at exactly v_x = 0, where the envelope admits
    2 pi G tau_peak / rho; this value is the safe one.
    """
    eta = params.losses.transmission_efficiency_forward
    return params.transmission_ratio * eta * (params.motor.peak_torque - params.motor.rotor_coulomb_friction)


def top_speed(params: EmlaParams) -> float:
    """Return the rod speed [m/s] at rated motor speed: omega_rated rho / (2 pi G).

    This is the ``rated_speed`` limit; at light load the voltage limit allows more for the XS 031
    set (the tests check that no-load motion at top speed is inside the envelope).
    """
    return params.motor.rated_speed / params.transmission_ratio

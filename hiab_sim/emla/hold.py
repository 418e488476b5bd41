"""What holds the machine while it rests between cycles: the EMLA's holding brake or its motor.

A ball or roller screw is back-drivable, so during the rest T_rest after each cycle something must
carry the static load f_x of the rest pose (the cycle's last sample; the next cycle starts from its
first). At standstill the motor-shaft torque that holds it is tau_h = f_x / k, k = 2 pi G / rho
(eq. ``torque_force`` with v_x = a_x = 0: no friction, no transmission loss, :mod:`hiab_sim.emla.drive`).

* ``hold: brake``: the spring-applied holding brake on the motor shaft carries the load, the motor
  carries no current. The brake must hold, |tau_h| <= M_4 at the first and the last pose
  (``brake_margin`` = 1 - max |tau_h| / M_4 >= 0). Its coil is energised while the motor moves
  (P_coil over the whole cycle, unless the drive losses of :mod:`hiab_sim.emla.losses` already
  count it sample by sample: ``brake_coil_power`` > 0 there) and de-energised during the rest.
  Each period has one release and one engagement: before moving, the motor takes the first pose's
  load and the coil is energised for the release (opening) time t_2; after the motion the motor holds
  the last pose for the engage (closing) time t_1 until the brake has closed. Transition energy at the drive:
  E_tr = (P_coil + P_cu(tau_first) + P_inv(tau_first)) t_2 + (P_cu(tau_last) + P_inv(tau_last)) t_1.
  The powered drive keeps its standby loss c_0 during the rest.
* ``hold: motor``: the motor holds the last pose through the rest: torque tau_h, copper loss
  3/2 R_s (tau_h / K_t)^2 (R_s at the winding temperature when the winding is hot,
  :mod:`hiab_sim.emla.electrothermal`), inverter loss c_0 + c_1 |i| + c_2 i^2, the released brake's
  coil power; tau_h enters the RMS torque over the period and the rest's loss heats the winding.

The transitions' 0.2 s of holding torque are counted in the energy but not in the RMS torque or the
winding temperature (0.4 % of a 53.75 s rest).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiab_sim.checks import check_choice
from hiab_sim.emla.brake import HoldingBrake
from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.drive import drive_state
from hiab_sim.emla.losses import inverter_loss
from hiab_sim.errors import InvalidInputError

#: The two ways the machine is held during the rest.
HOLD_MODES: tuple[str, ...] = ("brake", "motor")

__all__ = ["HOLD_MODES", "HoldingBrake", "RestHold", "rest_hold", "static_hold_torque"]


@dataclass(frozen=True)
class RestHold:
    """One EMLA during the rest (see the module docstring); powers at the drive's electrical input.

    Attributes:
        mode: ``brake`` or ``motor``.
        first_pose_torque: tau_h at the cycle's first sample [N m].
        last_pose_torque: tau_h at the cycle's last sample [N m].
        rest_torque: Motor torque during the rest [N m] (0 with the brake).
        rest_copper_loss_ref: c_r, the rest's copper loss at R_s,ref [W].
        rest_other_power: Inverter standby, inverter current and coil power during the rest [W]
            (not temperature dependent).
        standby_power: The part of ``rest_other_power`` that is the powered inverter's standby c_0 [W].
        transition_copper_ref: Copper energy of the release (first pose) and of the engagement (last
            pose) at R_s,ref [J], each to be scaled by R_s(T)/R_s,ref of its sample.
        transition_other_energy: Coil and inverter energy of the release and engagement beyond the
            standby already in ``rest_other_power`` [J].
        cycle_coil_energy: P_coil T_cycle [J] when the drive losses do not count the coil sample by
            sample (``drive_losses.brake_coil_power`` 0), else 0.
        brake_margin: 1 - max(|tau_first|, |tau_last|) / M_4 [-] (``brake``; None for ``motor``).
        d_rest_copper_loss_ref: d c_r / d f_last [W/N].
        d_rest_other_power: d rest_other_power / d f_last [W/N].
        d_transition_copper_ref: (d first part / d f_first, d last part / d f_last) [J/N].
        d_transition_other_energy: (d / d f_first, d / d f_last) [J/N].

    """

    mode: str
    first_pose_torque: float
    last_pose_torque: float
    rest_torque: float
    rest_copper_loss_ref: float
    rest_other_power: float
    standby_power: float
    transition_copper_ref: tuple[float, float]
    transition_other_energy: float
    cycle_coil_energy: float
    brake_margin: float | None
    d_rest_copper_loss_ref: float
    d_rest_other_power: float
    d_transition_copper_ref: tuple[float, float]
    d_transition_other_energy: tuple[float, float]


def static_hold_torque(params: EmlaParams, force: float) -> float:
    """Motor-shaft torque [N m] that holds a static rod force f_x [N] (v_x = a_x = 0): f_x / k."""
    state = drive_state(params, np.array([force]), np.zeros(1), np.zeros(1), exact=True)
    return float(state.motor_torque[0])


def _copper(params: EmlaParams, tau: float) -> tuple[float, float]:
    """(3/2 R_s,ref (tau / K_t)^2 [W], its derivative w.r.t. f_x [W/N]) at standstill."""
    m = params.motor
    k = params.transmission_ratio
    return 1.5 * m.stator_resistance * (tau / m.torque_constant) ** 2, 3.0 * m.stator_resistance * tau / (
        m.torque_constant**2 * k
    )


def _inverter(params: EmlaParams, tau: float) -> tuple[float, float]:
    """(P_inv [W], d P_inv / d f_x [W/N]) of the exact inverter loss at the holding current (0 when off)."""
    losses, m = params.losses, params.motor
    if not losses.inverter_on:
        return 0.0, 0.0
    p, d = inverter_loss(losses, np.array([tau / m.torque_constant]), exact=True)
    return float(p[0]), float(d[0]) / (m.torque_constant * params.transmission_ratio)


def rest_hold(params: EmlaParams, mode: str, first_force: float, last_force: float, cycle_time: float) -> RestHold:
    """Return what one EMLA draws and carries during the rest (see the module docstring).

    Args:
        params: The actuator (``params.brake`` is needed for ``brake``).
        mode: ``brake`` or ``motor``.
        first_force: Rod force f_x at the cycle's first sample [N] (the pose the next cycle leaves).
        last_force: Rod force f_x at the cycle's last sample [N] (the rest pose).
        cycle_time: The cycle's duration T [s] (the brake is released for all of it).

    """
    check_choice("hold", mode, HOLD_MODES)
    tau_first = static_hold_torque(params, first_force)
    tau_last = static_hold_torque(params, last_force)
    losses, brake = params.losses, params.brake
    cu_first, d_cu_first = _copper(params, tau_first)
    cu_last, d_cu_last = _copper(params, tau_last)
    inv_first, d_inv_first = _inverter(params, tau_first)
    inv_last, d_inv_last = _inverter(params, tau_last)
    standby = losses.inverter_constant_loss if losses.inverter_on else 0.0
    if mode == "motor":
        coil = brake.coil_power if brake is not None else (losses.brake_coil_power if losses.brake_on else 0.0)
        return RestHold(
            mode=mode,
            first_pose_torque=tau_first,
            last_pose_torque=tau_last,
            rest_torque=tau_last,
            rest_copper_loss_ref=cu_last,
            rest_other_power=inv_last + coil,
            standby_power=standby,
            transition_copper_ref=(0.0, 0.0),
            transition_other_energy=0.0,
            cycle_coil_energy=0.0,
            brake_margin=None,
            d_rest_copper_loss_ref=d_cu_last,
            d_rest_other_power=d_inv_last,
            d_transition_copper_ref=(0.0, 0.0),
            d_transition_other_energy=(0.0, 0.0),
        )
    if brake is None:
        raise InvalidInputError(f"{params.name}.holding_brake", None, "must be given in the EMLA file for hold: brake")
    t_rel, t_eng = brake.release_time, brake.engage_time
    return RestHold(
        mode=mode,
        first_pose_torque=tau_first,
        last_pose_torque=tau_last,
        rest_torque=0.0,
        rest_copper_loss_ref=0.0,
        rest_other_power=standby,
        standby_power=standby,
        transition_copper_ref=(cu_first * t_rel, cu_last * t_eng),
        transition_other_energy=(brake.coil_power + inv_first - standby) * t_rel + (inv_last - standby) * t_eng,
        cycle_coil_energy=0.0 if losses.brake_coil_power > 0.0 else brake.coil_power * cycle_time,
        brake_margin=1.0 - max(abs(tau_first), abs(tau_last)) / brake.holding_torque,
        d_rest_copper_loss_ref=0.0,
        d_rest_other_power=0.0,
        d_transition_copper_ref=(d_cu_first * t_rel, d_cu_last * t_eng),
        d_transition_other_energy=(d_inv_first * t_rel, d_inv_last * t_eng),
    )

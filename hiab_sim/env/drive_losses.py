"""The EMLA file's drive losses in the closed loop: the planner's transmission, inverter and brake, one model.

The simulated drives (:mod:`hiab_sim.emla.drive_sim`, :mod:`hiab_sim.env.plant.current_loop`) give the dq
currents, the motor-terminal energy int 3/2 v.i dt and the electromagnetic torque. What the planner's EMLA
model puts between the motor and the screw and between the motor terminals and the DC bus
(:mod:`hiab_sim.emla.losses`, composed in :mod:`hiab_sim.emla.model`) is added here through the planner's
own functions, in the smooth form the optimiser's energy is computed in (``exact=False``), so the
closed loop and the prediction count the same losses at the same boundary, the drive's DC input.

Transmission (gearbox and screw efficiency, eq. ``torque_torque`` with the loss torque tau_tr of
:func:`~hiab_sim.emla.losses.transmission_loss_torque`). With the rotor rigid on the slide (its
J_m k^2 is the slide's armature) the screw force f_sm solves

    f_sm + k tau_tr(f_sm, omega_m) = y,    y = k (tau_m - tau_f tanh(omega_m / omega_eps)) - J_m k^2 a_x,

solved by Newton's method on tau_tr and its d/df_sm (the left side rises monotonically in f_sm: its
slope is at least eta_back > 0); the rod force handed to the slide is f_sm + J_m k^2 a_x, with a_x the
slide's acceleration of the previous step (the rotor's inertial force one step late: J_m k^2 times the
change of a_x over 1 ms, about 1e-4 of the force on the default study). On the two-mass drive train
(:mod:`hiab_sim.env.plant.drivetrain`) the screw force is known at the step's start, f_sm = f_s + b_f v_m
(spring plus screw friction), and the motor side is driven by y - k tau_tr(f_sm, omega_m). The loss
power is tau_tr omega_m either way (>= 0, :mod:`hiab_sim.emla.losses`).

DC side (eq. of :mod:`hiab_sim.emla.model`), per drive over a physics step of length h, with the brake's
release factor s = s(v_x) of :func:`~hiab_sim.emla.losses.brake_release` at the rod speed of the step's
start, the motor-terminal energy E_m and the current amplitude |i_dq| at the drive's samples m (Simpson
weights w_m):

    E_dc = s (E_m + P_coil h) + sum_m w_m P_inv(s |i_dq|_m)        (P_inv: :func:`~hiab_sim.emla.losses.inverter_loss`)

The brake enters the energy only, in the planner's form: the simulated motor keeps carrying the load
below the brake speed (the rod stands there either way, |v_x| < v_b), and the share (1 - s) E_m it
would have saved is booked as ``brake_carried``, so the balance reads
E_dc = E_m + s P_coil h + E_inv - (1 - s) E_m.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import cast

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.drive_sim import DriveStep
from hiab_sim.emla.losses import DriveLosses, brake_release, inverter_loss, transmission_loss_torque

#: Newton steps of the transmission's inversion: the loss torque is piecewise almost linear in f_sm
#: (smooth |f_sm| within f_eps = 10 N), so two steps from the exact form's solution reach round-off.
NEWTON_STEPS = 3


@dataclass(frozen=True)
class _StackedLosses:
    """The drives' loss parameters as arrays, read by the planner's loss functions in one call for all drives.

    :func:`~hiab_sim.emla.losses.transmission_loss_torque` and :func:`~hiab_sim.emla.losses.inverter_loss`
    are elementwise in their parameters, so one call on (n,) arrays (columns (n, 1) for the inverter's
    per-sample currents) gives each drive what its own call gives, to the bit.
    """

    transmission_efficiency_forward: Array
    transmission_efficiency_backdriven: Array
    force_smoothing: Array
    inverter_constant_loss: Array
    inverter_current_loss: Array
    inverter_resistance: Array
    current_smoothing: Array

    @classmethod
    def of(cls, losses: tuple[DriveLosses, ...], shape: tuple[int, ...]) -> DriveLosses:
        """The stacked parameters of ``losses``, each field reshaped to ``shape``."""

        def stack(field: str) -> Array:
            return np.array([getattr(loss, field) for loss in losses], dtype=float).reshape(shape)

        fields = (
            "transmission_efficiency_forward",
            "transmission_efficiency_backdriven",
            "force_smoothing",
            "inverter_constant_loss",
            "inverter_current_loss",
            "inverter_resistance",
            "current_smoothing",
        )
        return cast(DriveLosses, cls(*(stack(field) for field in fields)))


class DriveLossModel:
    """The drive losses of n EMLAs (module docstring); one per physics, built from the EMLA set.

    Args:
        emlas: The EMLAs in the drives' order (their ``losses``, ``transmission_ratio``, rotor inertia
            and friction smoothing speed).

    """

    def __init__(self, emlas: Iterable[EmlaParams]) -> None:
        self.params = tuple(emlas)
        self.losses = tuple(p.losses for p in self.params)
        self.ratio = np.array([p.transmission_ratio for p in self.params])
        self.rotor_mass = np.array([p.motor.rotor_inertia * p.transmission_ratio**2 for p in self.params])
        self.omega_eps = np.array([p.motor.friction_smoothing_speed for p in self.params])
        self.transmission_on = any(loss.transmission_on for loss in self.losses)
        n = len(self.params)
        self._transmission = np.array([loss.transmission_on for loss in self.losses])
        self._inverter = np.array([loss.inverter_on for loss in self.losses])
        self._stacked = _StackedLosses.of(self.losses, (n,))
        self._columns = _StackedLosses.of(self.losses, (n, 1))
        self._coil_power = np.array([loss.brake_coil_power for loss in self.losses])
        self._braked = [j for j, loss in enumerate(self.losses) if loss.brake_on]

    def loss_torque(self, screw_force: Array, motor_speed: Array) -> tuple[Array, Array]:
        """(tau_tr [N m], d tau_tr / d f_sm [m]) per drive at the screw forces [N] and motor speeds [rad/s].

        One call of the planner's function on all drives (:class:`_StackedLosses`); 0 where a drive's
        transmission is lossless.
        """
        t, d_f, _ = transmission_loss_torque(
            self._stacked,
            np.asarray(screw_force, dtype=float),
            np.asarray(motor_speed, dtype=float),
            self.ratio,  # type: ignore[arg-type]
            self.omega_eps,  # type: ignore[arg-type]
            exact=False,
        )
        on = self._transmission
        return np.where(on, t, 0.0), np.where(on, d_f, 0.0)

    def screw_force(self, available: Array, motor_speed: Array) -> tuple[Array, Array]:
        """(f_sm [N], tau_tr [N m]) solving f_sm + k tau_tr(f_sm, omega_m) = y for y = ``available`` [N]."""
        y = np.asarray(available, dtype=float)
        if not self.transmission_on:
            return y.copy(), np.zeros_like(y)
        # Start from the exact form's solution: f = y eta_fwd driving, y / eta_back backdriven.
        forward = np.array([loss.transmission_efficiency_forward for loss in self.losses])
        backward = np.array([loss.transmission_efficiency_backdriven for loss in self.losses])
        driving = y * np.sign(motor_speed) >= 0.0
        force = np.where(driving, y * forward, y / backward)
        for _ in range(NEWTON_STEPS):
            tau, slope = self.loss_torque(force, motor_speed)
            force = force - (force + self.ratio * tau - y) / (1.0 + self.ratio * slope)
        tau, _ = self.loss_torque(force, motor_speed)
        return force, tau

    def rigid_rod_force(self, drive_force: Array, motor_speed: Array, acceleration: Array) -> tuple[Array, Array]:
        """(rod force [N] for the slide, tau_tr [N m]) from k (tau_m - tau_f) [N] and the slide's a_x [m/s^2]."""
        inertial = self.rotor_mass * np.asarray(acceleration, dtype=float)
        force, tau = self.screw_force(np.asarray(drive_force, dtype=float) - inertial, motor_speed)
        return force + inertial, tau

    def dc_energy(self, step: DriveStep, rod_velocity: Array, h: float) -> tuple[Array, Array, Array, Array]:
        """(E_dc, E_inv, E_coil, E_brake_carried) [J] per drive over the step (module docstring)."""
        n = len(self.params)
        release = np.ones(n)
        for j in self._braked:  # the brake's release factor s(v_x); 1 where no brake is modelled
            loss = self.losses[j]
            release[j] = float(brake_release(loss, np.asarray(float(rod_velocity[j])), exact=False)[0])
        motor = np.asarray(step.electrical_energy, dtype=float)
        coil = release * self._coil_power * h
        magnitudes = step.current_samples
        weights = step.sample_weights
        inverter = np.zeros(n)
        if magnitudes is None or weights is None:
            for j, loss in enumerate(self.losses):
                if loss.inverter_on:
                    amplitude = np.array([np.hypot(float(step.i_d[j]), float(step.i_q[j]))])
                    inverter[j] = h * float(inverter_loss(loss, release[j] * amplitude, exact=False)[0][0])
        elif self._inverter.any():
            power = inverter_loss(self._columns, release[:, None] * magnitudes, exact=False)[0]
            for row in np.flatnonzero(self._inverter).tolist():
                inverter[row] = float(weights @ power[row])
        carried = (1.0 - release) * motor
        dc = release * motor + coil + inverter
        return dc, inverter, coil, carried

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

import numpy as np
from numpy.typing import NDArray

from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.drive_sim import DriveStep
from hiab_sim.emla.losses import brake_release, inverter_loss, transmission_loss_torque

Array = NDArray[np.float64]

#: Newton steps of the transmission's inversion: the loss torque is piecewise almost linear in f_sm
#: (smooth |f_sm| within f_eps = 10 N), so two steps from the exact form's solution reach round-off.
NEWTON_STEPS = 3


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

    def loss_torque(self, screw_force: Array, motor_speed: Array) -> tuple[Array, Array]:
        """(tau_tr [N m], d tau_tr / d f_sm [m]) per drive at the screw forces [N] and motor speeds [rad/s]."""
        tau = np.zeros(len(self.params))
        slope = np.zeros(len(self.params))
        for j, loss in enumerate(self.losses):
            if not loss.transmission_on:
                continue
            t, d_f, _ = transmission_loss_torque(
                loss,
                np.asarray(screw_force[j], dtype=float),
                np.asarray(motor_speed[j], dtype=float),
                float(self.ratio[j]),
                float(self.omega_eps[j]),
                exact=False,
            )
            tau[j], slope[j] = float(t), float(d_f)
        return tau, slope

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
        dc, inverter, coil, carried = (np.zeros(n) for _ in range(4))
        magnitudes = step.current_samples
        weights = step.sample_weights
        for j, loss in enumerate(self.losses):
            s = float(brake_release(loss, np.asarray(float(rod_velocity[j])), exact=False)[0])
            motor = float(step.electrical_energy[j])
            coil[j] = s * loss.brake_coil_power * h
            if loss.inverter_on:
                if magnitudes is None or weights is None:
                    amplitude = np.array([np.hypot(float(step.i_d[j]), float(step.i_q[j]))])
                    inverter[j] = h * float(inverter_loss(loss, s * amplitude, exact=False)[0][0])
                else:
                    inverter[j] = float(weights @ inverter_loss(loss, s * magnitudes[j], exact=False)[0])
            carried[j] = (1.0 - s) * motor
            dc[j] = s * motor + coil[j] + inverter[j]
        return dc, inverter, coil, carried

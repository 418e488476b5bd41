"""The closed loop's drive losses: the planner's transmission efficiency and brake as the simulated drive has them."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hiab_sim.emla import load_emla_set
from hiab_sim.emla.drive_sim import DriveArrays, DriveSimulator
from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.env.drive_losses import DriveLossModel

EMLAS = load_emla_set()  # emla_xs031.yaml: eta_fwd 0.87, eta_back 0.862, 21.6 W coil, brake only between cycles
LOSSES = DriveLossModel(EMLAS)
#: The same drives with the brake engaging inside the cycle below 1 mm/s (the EMLA file's earlier setting).
BRAKED = EmlaSet(*(replace(p, losses=replace(p.losses, brake_speed=1e-3)) for p in EMLAS), battery=EMLAS.battery)
SPEED = np.array([300.0, -200.0, 150.0])  # motor speeds [rad/s], far from the friction smoothing (1 rad/s)


def test_the_screw_delivers_the_forward_efficiency_of_the_drive_force() -> None:
    """Motor driving the load: the screw force is eta_fwd = 0.87 of the drive's force (power out / power in)."""
    drive = np.array([50e3, -30e3, 10e3])  # same sign as the speed: the motor drives
    screw, tau = LOSSES.screw_force(drive, SPEED)
    np.testing.assert_allclose(screw / drive, 0.87, rtol=1e-3)  # smooth |f| within f_eps = 10 N
    k = LOSSES.ratio
    np.testing.assert_allclose(screw + k * tau, drive, rtol=1e-12)


def test_a_backdriven_screw_returns_the_backdriven_efficiency_of_its_power() -> None:
    """The load driving the motor: the drive's force is eta_back = 0.862 of the screw force."""
    drive = np.array([-50e3, 30e3, -10e3])  # opposite to the speed: the load drives the motor
    screw, _ = LOSSES.screw_force(drive, SPEED)
    np.testing.assert_allclose(drive / screw, 0.862, rtol=1e-3)


def test_the_rotor_inertia_is_outside_the_transmission() -> None:
    """The rod force carries the rotor's inertial force J_m k^2 a_x whole; the rest passes the screw's efficiency."""
    drive = np.array([50e3, -30e3, 10e3])
    acceleration = np.array([0.2, -0.1, 0.3])  # m/s^2
    rod, _ = LOSSES.rigid_rod_force(drive, SPEED, acceleration)
    inertial = np.array([p.motor.rotor_inertia * p.transmission_ratio**2 for p in EMLAS]) * acceleration
    np.testing.assert_allclose(rod - inertial, 0.87 * (drive - inertial), rtol=1e-3)


def test_the_dc_input_balances_the_terminals_inverter_coil_and_brake() -> None:
    """E_dc = E_motor + E_inverter + E_coil - E_carried, with the brake released while moving and engaged at rest.

    The shipped file closes the brake only between cycles: at a standstill inside the cycle the coil
    still draws 21.6 W and nothing is carried. With the brake engaging below 1 mm/s: moving (1 m/s),
    the coil draws 21.6 W over the step and nothing is carried; at rest no coil, the motor's whole
    terminal energy is the brake's, and the inverter draws its standby c0 = 20 W only.
    """
    drives = DriveSimulator(DriveArrays.from_params(EMLAS), 500.0)
    drives.reset(0.0, [20.0, -10.0, 5.0])
    h = 1e-3
    step = drives.step(np.array([20.0, -10.0, 5.0]), SPEED, h)
    dc, _, coil, carried = LOSSES.dc_energy(step, np.zeros(3), h)  # the shipped file: no brake in the cycle
    np.testing.assert_allclose(coil, 21.6 * h)  # the coil stays energised at a standstill inside the cycle
    np.testing.assert_allclose(carried, 0.0, atol=1e-12)
    braked = DriveLossModel(BRAKED)
    dc, inverter, coil, carried = braked.dc_energy(step, np.ones(3), h)
    np.testing.assert_allclose(coil, 21.6 * h)
    np.testing.assert_allclose(carried, 0.0, atol=1e-12)
    np.testing.assert_allclose(dc, step.electrical_energy + inverter + coil, rtol=1e-12)
    dc, inverter, coil, carried = braked.dc_energy(step, np.zeros(3), h)
    np.testing.assert_allclose(coil, 0.0)
    np.testing.assert_allclose(carried, step.electrical_energy, rtol=1e-12)
    np.testing.assert_allclose(inverter, 20.0 * h, rtol=1e-12)
    np.testing.assert_allclose(dc, inverter, rtol=1e-12)

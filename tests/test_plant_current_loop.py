"""The discrete current loop: convergence to the continuous loop, its energy balance, dead time and inverter loss."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from hiab_sim.emla import load_emla_set
from hiab_sim.emla.drive_sim import DriveArrays, DriveSimulator
from hiab_sim.env.drive_losses import DriveLossModel
from hiab_sim.env.plant.config import CurrentLoop
from hiab_sim.env.plant.current_loop import DiscreteCurrentLoop
from hiab_sim.env.plant.sensors import CurrentSensorError

EMLAS = load_emla_set()
DRIVES = DriveArrays.from_params(EMLAS)
LOSSES = DriveLossModel(EMLAS)
MOVING = np.ones(3)  # rod speed [m/s], far above the brake speed: the brake is released (s = 1)
H = 1e-3
SPEED = np.array([300.0, -200.0, 100.0])  # motor speeds [rad/s]


def _loop(rate: float, dead_time: float = 0.0) -> CurrentLoop:
    return CurrentLoop(True, rate, 500.0, dead_time, 565.0)


def _run(sim: DriveSimulator, steps: int = 40) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """References 20/-10/5 A, then 5/3/-2 A, at held speeds: (i_q, electrical, copper, torque omega h, inverter)."""
    sim.reset(0.0, 0.0)
    currents, electrical, copper, mechanical, inverter = [], np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    for k in range(steps):
        reference = np.array([20.0, -10.0, 5.0]) if k < steps // 2 else np.array([5.0, 3.0, -2.0])
        step = sim.step(reference, SPEED, H)
        currents.append(step.i_q.copy())
        electrical += step.electrical_energy
        copper += step.copper_energy
        mechanical += step.torque * SPEED * H
        inverter += LOSSES.dc_energy(step, MOVING, H)[1]
    return np.array(currents), electrical, copper, mechanical, inverter


def test_discrete_loop_converges_to_the_continuous_loop_as_its_rate_rises() -> None:
    """Current and energy errors to the continuous IMC loop fall about as 1/f_s (the one-period computation delay)."""
    continuous = _run(DriveSimulator(DRIVES, 500.0))
    errors, energy = [], []
    for rate in (8e3, 32e3, 128e3):
        discrete = _run(DiscreteCurrentLoop(DRIVES, _loop(rate), CurrentSensorError(None, 3, 1.0), H))
        errors.append(np.abs(discrete[0] - continuous[0]).max())
        energy.append(np.abs(discrete[1] - continuous[1]).max() / np.abs(continuous[1]).max())
    assert errors[0] > 2.5 * errors[1] > 2.5**2 * errors[2]
    assert errors[2] < 0.1  # A, of 20 A steps
    assert energy[2] < 5e-4


def test_drive_energy_balance_closes_with_the_discrete_loop() -> None:
    """Electrical energy = copper loss + mechanical work + change of magnetic energy, to Simpson's accuracy.

    Dead time on: the applied voltage differs from the command, and the balance uses the applied one.
    """
    sim = DiscreteCurrentLoop(DRIVES, _loop(8e3, dead_time=2e-6), CurrentSensorError(None, 3, 1.0), H)
    _, electrical, copper, mechanical, _ = _run(sim)
    stored = DRIVES.magnetic_energy(sim.i_d, sim.i_q)  # from zero current
    np.testing.assert_allclose(electrical, copper + mechanical + stored, rtol=1e-6, atol=1e-6)


def test_dead_time_is_rejected_by_the_integrator_in_steady_state() -> None:
    """With 2 us dead time (11.5 V) the PI loop still settles on its reference; the delay costs no steady error."""
    sim = DiscreteCurrentLoop(DRIVES, _loop(8e3, dead_time=2e-6), CurrentSensorError(None, 3, 1.0), H)
    sim.reset(0.0, 0.0)
    for _ in range(100):
        step = sim.step(np.array([20.0, -10.0, 5.0]), SPEED, H)
    np.testing.assert_allclose(step.i_q, [20.0, -10.0, 5.0], atol=1e-3)
    np.testing.assert_allclose(step.i_d, 0.0, atol=1e-3)


def test_inverter_loss_at_constant_current_is_the_loss_formula() -> None:
    """At a settled current the inverter's loss over a step is the EMLA file's (c0 + c1 |i| + c2 |i|^2) h.

    c0 = 20 W, c1 = 4 W/A, c2 = 0.075 ohm as emla_xs031.yaml's drive_losses write them; the plant has no
    inverter-loss data of its own. The closed loop charges the planner's smooth form, whose |i| lies within
    i_eps = 0.01 A below the exact one (hiab_sim.emla.losses): within c1 i_eps h of the formula.
    """
    loop = _loop(8e3)
    sim = DiscreteCurrentLoop(DRIVES, loop, CurrentSensorError(None, 3, 1.0), H)
    sim.reset(0.0, [20.0, -10.0, 5.0])
    for _ in range(20):
        step = sim.step(np.array([20.0, -10.0, 5.0]), np.zeros(3), H)
    magnitude = np.array([20.0, 10.0, 5.0])
    expected = (20.0 + 4.0 * magnitude + 0.075 * magnitude**2) * H
    charged = LOSSES.dc_energy(step, MOVING, H)[1]
    assert np.all(charged <= expected) and np.all(expected - charged <= 4.0 * 0.01 * H * (1 + 1e-6))


def test_current_sensor_offset_shifts_the_current_by_the_offset() -> None:
    """The loop regulates the measurement: a +0.2 A q-axis offset leaves the drive 0.2 A below its reference."""
    from hiab_sim.env.plant.config import Sensors

    sensors = Sensors(True, 65536, 0.0, 0.2, 0.0)
    sim = DiscreteCurrentLoop(DRIVES, _loop(8e3), CurrentSensorError(sensors, 3, 8.0), H)
    sim.reset(0.0, 0.0)
    for _ in range(60):
        step = sim.step(np.array([20.0, -10.0, 5.0]), SPEED, H)
    np.testing.assert_allclose(step.i_q, [19.8, -10.2, 4.8], atol=1e-3)


def test_a_rate_that_does_not_divide_the_physics_step_is_rejected() -> None:
    """f_s h must be an integer: 7.5 kHz at 1 ms names current_loop.rate_Hz."""
    from hiab_sim.errors import InvalidInputError

    with pytest.raises(InvalidInputError, match=r"current_loop\.rate_Hz"):
        DiscreteCurrentLoop(
            DRIVES, dataclasses.replace(_loop(8e3), rate_Hz=7500.0), CurrentSensorError(None, 3, 1.0), H
        )

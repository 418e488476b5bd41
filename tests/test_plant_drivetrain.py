"""The two-mass drive train alone: resonance, free play, energy balance (a MuJoCo rod, the Python motor side)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from hiab_sim.env.plant.config import DriveTrain
from hiab_sim.env.plant.drivetrain import TwoMassDriveTrain, coupled_step, locked_rod_frequency_Hz

ROD_XML = """<mujoco><option timestep="{h}" integrator="implicitfast" gravity="0 0 0"/>
<worldbody><body><joint name="x" type="slide" axis="1 0 0"/><geom size="0.05" mass="{mass}"/></body></worldbody>
<actuator><general joint="x" gaintype="fixed" gainprm="1" biastype="affine" biasprm="0 0 0"/></actuator></mujoco>"""


def _rod(mass: float, h: float) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(ROD_XML.format(h=h, mass=mass))
    return model, mujoco.MjData(model)


def _train(
    stiffness: float, zeta: float, backlash: float, motor_mass: float, viscous: float = 0.0
) -> TwoMassDriveTrain:
    data = DriveTrain(True, zeta, backlash, 0.0)
    return TwoMassDriveTrain(data, np.array([stiffness]), np.array([motor_mass]), np.array([viscous]))


def _simulate(train: TwoMassDriveTrain, rod_mass: float, force: float, h: float, steps: int):  # type: ignore[no-untyped-def]
    model, data = _rod(rod_mass, h)
    ids = np.array([0])
    log = np.empty((steps, 5))
    dissipated = 0.0
    work = 0.0
    for k in range(steps):
        dissipated += float(coupled_step(train, model, data, ids, ids, np.array([force]), h)[0])
        work += force * h * float(train.velocity[0])  # the drive's force on the motor side, symplectic
        log[k] = (k * h, train.position[0], data.qpos[0], train.velocity[0], data.qvel[0])
    return log, dissipated, work, model, data


def test_force_step_rings_at_the_two_mass_frequency() -> None:
    """A force step on the motor side makes the deflection ring at sqrt(k (1/m_m + 1/m_L)) / 2 pi within 1 %.

    The frequency is read from the zero crossings of the deflection about its mean over 20 periods
    of a MuJoCo rod (mass m_L) on the spring of a Python motor side (mass m_m).
    """
    k, m_m, m_l, h = 1.0e6, 100.0, 50.0, 1e-4
    expected = math.sqrt(k * (1 / m_m + 1 / m_l)) / (2 * math.pi)
    train = _train(k, 0.0, 0.0, m_m)
    steps = int(20 / expected / h)
    log, _, _, _, _ = _simulate(train, m_l, 1000.0, h, steps)
    deflection = log[:, 1] - log[:, 2]
    signal = deflection - deflection.mean()
    crossings = np.flatnonzero(np.diff(np.sign(signal)) > 0)
    times = log[crossings, 0] - signal[crossings] * h / (signal[crossings + 1] - signal[crossings])
    measured = (len(times) - 1) / (times[-1] - times[0])
    assert measured == pytest.approx(expected, rel=0.01)
    # The mean deflection of the free pair under a force F is F m_L / (k (m_m + m_L)).
    assert deflection.mean() == pytest.approx(1000.0 * m_l / (k * (m_m + m_l)), rel=0.02)


def test_locked_rod_frequency_is_the_lowest_two_mass_frequency() -> None:
    """sqrt(k/m_m) / 2 pi lies below the two-mass frequency for every load mass and is its limit for a heavy load."""
    lock = float(locked_rod_frequency_Hz(np.array([1.87e8]), np.array([30319.0]))[0])
    for load in (10.0, 1e3, 1e5, 1e9):
        two_mass = math.sqrt(1.87e8 * (1 / 30319.0 + 1 / load)) / (2 * math.pi)
        assert lock < two_mass
    assert lock == pytest.approx(math.sqrt(1.87e8 * (1 / 30319.0 + 1e-9)) / (2 * math.pi), rel=1e-4)


def test_backlash_leaves_a_dead_band_of_its_width() -> None:
    """Within +-b of zero deflection no force passes; beyond it the force is k (|d| - b); both paths agree."""
    k, play = 1.0e7, 2.0e-4
    train = _train(k, 0.0, play, 10.0)
    rod = np.zeros(1)
    for d in np.linspace(-5e-4, 5e-4, 41):
        train.position = np.array([d])
        force = float(train.spring_force(rod, np.zeros(1))[0])
        expected = k * math.copysign(max(abs(d) - play / 2, 0.0), d)
        assert force == pytest.approx(expected, abs=1e-6)
        ctrl, k_c, c_c = train.rod_actuator(rod, 1e-3)
        assert float(ctrl[0] - k_c[0] * rod[0] - c_c[0] * 0.0) == pytest.approx(expected, abs=1e-6)


def test_backlash_lets_the_motor_side_travel_freely_across_the_gap() -> None:
    """A small force moves the motor side across the gap with a = F / m_m before any force reaches the rod."""
    k, play, m_m, force, h = 1.0e7, 2.0e-4, 10.0, 5.0, 1e-4
    train = _train(k, 0.0, play, m_m)
    train.position = np.array([-play / 2])  # at the far edge of the gap
    log, _, _, _, _ = _simulate(train, 50.0, force, h, 200)
    # The motor side crosses 2 b in t = sqrt(2 * 2b * m / F) = 0.04 s; before that the rod stays put.
    crossing = math.sqrt(2 * play * m_m / force)
    before = log[:, 0] < 0.9 * crossing
    assert np.all(np.abs(log[before, 2]) < 1e-12)
    travel = log[before, 1] + play / 2
    t = log[before, 0] + h  # the log holds the state after step k + 1
    # Symplectic Euler under a constant acceleration a: x_N = a h^2 N (N + 1) / 2 = a (t^2 + t h) / 2.
    np.testing.assert_allclose(travel, 0.5 * force / m_m * (t * t + t * h), rtol=1e-9)


def test_drive_train_energy_balance_closes() -> None:
    """Work of the drive = kinetic energy of both masses + spring energy + dissipated (damping, screw friction).

    Free play, damping and screw friction on; 1 s of a force step at h = 0.1 ms: the balance closes to
    the integrator's accuracy (below 0.5 % of the work).
    """
    h = 1e-4
    train = _train(1.0e6, 0.1, 1e-4, 100.0, viscous=200.0)
    _, dissipated, work, _, data = _simulate(train, 50.0, 2000.0, h, 10000)
    kinetic = float(train.kinetic_energy()[0]) + 0.5 * 50.0 * float(data.qvel[0]) ** 2
    spring = float(train.spring_energy(data.qpos[:1])[0])
    assert dissipated > 0.05 * work
    assert work == pytest.approx(kinetic + spring + dissipated, rel=5e-3)

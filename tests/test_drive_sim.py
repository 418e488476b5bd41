"""The simulated EMLA drive on its own: stator L/R dynamics, voltage limit, power balance, exact steps."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from hiab_sim.emla import load_emla_set
from hiab_sim.emla.drive_sim import DriveArrays, DriveSimulator, plant_step
from hiab_sim.emla.pmsm import current_derivatives
from hiab_sim.errors import InvalidInputError

EMLAS = load_emla_set()
DRIVES = DriveArrays.from_params(EMLAS)
LIFT = EMLAS.lift
MOTOR = LIFT.motor


def _closed_loop_ivp(sim: DriveSimulator, i0: np.ndarray, ref_q: float, omega: float, t_end: float):
    """Integrate eq. dq0voltage under the limited controller with LSODA (lift drive only)."""
    one = DriveArrays.from_params([LIFT])
    shadow = DriveSimulator(one, bandwidth_hz=sim.bandwidth / (2 * math.pi))

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        v_d, v_q = shadow.limited_command(y[:1], y[1:], np.zeros(1), np.array([ref_q]), np.array([omega]))
        di_d, di_q = current_derivatives(MOTOR, y[0], y[1], omega, v_d[0], v_q[0])
        return np.array([di_d, di_q])

    return solve_ivp(rhs, (0.0, t_end), i0, method="LSODA", rtol=1e-10, atol=1e-10, dense_output=True, max_step=1e-5)


def test_voltage_step_settles_with_the_stator_time_constant() -> None:
    """Open loop at standstill, a q-voltage step gives i_q = V/R (1 - exp(-t R/L)): the stator's L/R."""
    tau = MOTOR.Lq / MOTOR.stator_resistance
    volts = 10.0
    for t in (0.1 * tau, tau, 3.0 * tau):
        _, i_q, _, charge = plant_step(DRIVES, np.zeros(3), np.zeros(3), np.zeros(3), np.full(3, volts), np.zeros(3), t)
        expected = volts / MOTOR.stator_resistance * (1.0 - math.exp(-t / tau))
        assert i_q[0] == pytest.approx(expected, rel=1e-12)
        integral = volts / MOTOR.stator_resistance * (t - tau * (1.0 - math.exp(-t / tau)))
        assert charge[0] == pytest.approx(integral, rel=1e-10)


@settings(max_examples=20, deadline=None)
@given(
    st.floats(-40.0, 40.0),
    st.floats(-40.0, 40.0),
    st.floats(-300.0, 300.0),
    st.floats(-400.0, 400.0),
    st.floats(-200.0, 200.0),
)
def test_plant_step_matches_a_numerical_integration_at_speed(
    i_d: float, i_q: float, v_d: float, omega: float, v_q: float
) -> None:
    """The closed-form 2x2 exponential equals LSODA on eq. dq0voltage (voltage and speed held) to 1e-7 A."""
    dt = 1e-3
    sol = solve_ivp(
        lambda _t, y: np.array(current_derivatives(MOTOR, y[0], y[1], omega, v_d, v_q)),
        (0.0, dt),
        [i_d, i_q],
        method="LSODA",
        rtol=1e-12,
        atol=1e-12,
    )
    x1, x2, _, _ = plant_step(
        DRIVES, np.full(3, i_d), np.full(3, i_q), np.full(3, v_d), np.full(3, v_q), np.full(3, omega), dt
    )
    np.testing.assert_allclose([x1[0], x2[0]], sol.y[:, -1], atol=1e-7)


def test_current_reference_step_follows_the_plant_under_the_controller() -> None:
    """A q-current step at standstill matches LSODA on plant + controller and settles within 5 / w_c."""
    sim = DriveSimulator(DRIVES, bandwidth_hz=500.0)
    h, steps, ref = 2e-4, 20, 30.0
    sol = _closed_loop_ivp(sim, np.zeros(2), ref, 0.0, h * steps)
    for k in range(1, steps + 1):
        result = sim.step(np.array([ref, ref, ref]), np.zeros(3), h)
        np.testing.assert_allclose([result.i_d[0], result.i_q[0]], sol.sol(k * h), atol=1e-6)
    settled = 5.0 / sim.bandwidth
    assert steps * h >= settled and abs(sim.i_q[0] - ref) < 0.01 * ref


def test_voltage_limit_engages_at_high_speed_and_caps_the_current() -> None:
    """Near the back-EMF limit a large q-current request is capped: |v_dq| <= V_max, i_q stays short of it.

    The saturated steps hold the limited voltage over sub-steps (zero-order hold); they converge to
    LSODA on plant + continuous limited controller at first order in the sub-step.
    """
    omega = 0.95 * DRIVES.voltage_limit[0] / (MOTOR.pole_pairs * MOTOR.flux_linkage)  # back-EMF at 95 % of V_max
    ref = 50.0
    h = 1e-3
    errors = {}
    for substeps in (20, 80):
        sim = DriveSimulator(DRIVES, bandwidth_hz=500.0, saturated_substeps=substeps)
        sol = _closed_loop_ivp(sim, np.zeros(2), ref, omega, 0.02)
        worst = 0.0
        for k in range(1, 21):
            result = sim.step(np.full(3, ref), np.full(3, omega), h)
            assert result.voltage_limited[0]
            assert math.hypot(result.v_d[0], result.v_q[0]) <= DRIVES.voltage_limit[0] * (1 + 1e-12)
            worst = max(worst, float(np.max(np.abs([result.i_d[0], result.i_q[0]] - sol.sol(k * h)))))
        errors[substeps] = worst
        assert sim.i_q[0] < 0.5 * ref  # the last 5 % of V_max cannot drive 50 A through R_s and w_e L
    assert errors[80] < errors[20] / 2.5 and errors[80] < 0.05


@pytest.mark.sim
def test_power_balance_of_a_drive_turning_a_rotor() -> None:
    """Electrical energy = load work + copper + rotor friction + kinetic and magnetic energy change, to 1e-5.

    The rotor (J omega' = tau_m - tau_f - tau_load) is integrated with the drive held at the step's
    mid-point speed (fixed-point iteration), so the mechanical side is energy-consistent; copper loss
    is the trapezoid rule on the current samples, the only term that is not exact.
    """
    sim = DriveSimulator(DRIVES, bandwidth_hz=500.0)
    inertia = DRIVES.rotor_inertia + 0.002  # rotor + a flywheel [kg m^2]
    load = np.array([4.0, -3.0, 1.0])  # load torque [N m]
    h, steps = 5e-5, 4000
    omega = np.array([50.0, -80.0, 300.0])
    omega0 = omega.copy()
    electrical, load_work, friction_work, copper = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    i_sq = sim.i_d**2 + sim.i_q**2
    omega_new = omega.copy()
    for k in range(steps):
        ref = np.array([20.0, 35.0, -10.0]) * (1.0 if k < steps // 2 else -0.5)
        start = (sim.i_d, sim.i_q)
        for _ in range(6):
            sim.i_d, sim.i_q = start
            mid = 0.5 * (omega + omega_new)
            result = sim.step(ref, mid, h)
            omega_new = omega + h * (result.torque - result.friction_torque - load) / inertia
        electrical += result.electrical_energy
        new_sq = result.i_d**2 + result.i_q**2
        copper += 1.5 * DRIVES.resistance * 0.5 * (i_sq + new_sq) * h
        i_sq = new_sq
        friction_work += result.friction_torque * mid * h
        load_work += load * mid * h
        omega = omega_new
    kinetic = 0.5 * inertia * (omega**2 - omega0**2)
    magnetic = DRIVES.magnetic_energy(sim.i_d, sim.i_q)
    balance = load_work + copper + friction_work + kinetic + magnetic
    scale = np.abs(load_work) + copper + np.abs(friction_work) + np.abs(kinetic)
    np.testing.assert_array_less(np.abs(electrical - balance), 1e-5 * scale)


def test_bad_simulator_settings_are_rejected() -> None:
    """A non-positive bandwidth or too few saturated sub-steps name the field."""
    with pytest.raises(InvalidInputError, match="bandwidth_hz"):
        DriveSimulator(DRIVES, bandwidth_hz=0.0)
    with pytest.raises(InvalidInputError, match="saturated_substeps"):
        DriveSimulator(DRIVES, saturated_substeps=1)

"""Transient checks: integrating the current dynamics settles on the steady-state power formula."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hiab_sim.emla import EmlaParams, abc_to_dq0, dq0_to_abc, electrical_power, load_emla_set, operating_point
from hiab_sim.emla.pmsm import current_derivatives, electromagnetic_torque

EMLAS = load_emla_set("paper")
SALIENT_LIFT = dataclasses.replace(EMLAS.lift, motor=dataclasses.replace(EMLAS.lift.motor, Ld=1.6e-3, Lq=2.8e-3))


@pytest.mark.parametrize(
    ("params", "force", "velocity"),
    [
        (EMLAS.lift, 60e3, 0.12),  # motoring
        (EMLAS.telescope, -20e3, 0.3),  # generating
        (SALIENT_LIFT, 40e3, -0.08),  # Ld != Lq, motoring while retracting
    ],
    ids=["lift-motoring", "telescope-generating", "salient-lift"],
)
def test_pi_current_loop_settles_on_the_steady_state_electrical_power(
    params: EmlaParams, force: float, velocity: float
) -> None:
    """The dq current loop settles on electrical_power() within 1e-6 relative.

    PI current controller without decoupling terms, constant load and speed; the settled
    3/2 (V_d i_d + V_q i_q) is compared with the steady-state formula.
    """
    motor = params.motor
    op = operating_point(params, force, velocity, 0.0)
    omega = float(op.motor_speed)
    i_ref = np.array([0.0, float(op.i_q)])
    bandwidth = 2 * np.pi * 300.0  # rad/s
    kp = bandwidth * np.array([motor.Ld, motor.Lq])  # pole-zero cancelling PI per axis
    ki = bandwidth * motor.stator_resistance

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        current, integral = y[:2], y[2:]
        error = i_ref - current
        v = kp * error + ki * integral
        di_d, di_q = current_derivatives(motor, current[0], current[1], omega, v[0], v[1])
        return np.array([di_d, di_q, error[0], error[1]])

    sol = solve_ivp(rhs, (0.0, 0.25), np.zeros(4), method="LSODA", rtol=1e-11, atol=1e-12)
    assert sol.success
    current, integral = sol.y[:2, -1], sol.y[2:, -1]
    v = kp * (i_ref - current) + ki * integral
    p_settled = 1.5 * (v[0] * current[0] + v[1] * current[1])
    p_model = float(electrical_power(params, force, velocity, 0.0))
    assert abs(p_settled - p_model) <= 1e-6 * abs(p_model)
    np.testing.assert_allclose(v, [op.v_d, op.v_q], rtol=1e-6, atol=1e-6)
    assert electromagnetic_torque(motor, *current) == pytest.approx(float(op.motor_torque), rel=1e-6)


def test_phase_frame_machine_fed_the_model_voltages_draws_the_model_power() -> None:
    """A plain abc circuit fed with the model's voltages draws the model's power (1e-6 relative).

    Three phase windings (R, L, back-EMF -omega_e Phi sin(theta_e - s_k)) fed with the inverse Park
    transform of the model's (V_d, V_q) settle to phase power sum v_k i_k = P_elec and to dq
    currents (0, i_q): the dq model and its 3/2 factor agree with the phase-frame circuit.
    """
    params = EMLAS.lift
    motor = params.motor
    force, velocity = 70e3, 0.1
    op = operating_point(params, force, velocity, 0.0)
    omega_e = motor.pole_pairs * float(op.motor_speed)
    shifts = np.array([0.0, 2 * np.pi / 3, -2 * np.pi / 3])
    v_dq0 = np.array([float(op.v_d), float(op.v_q), 0.0])

    def phase_voltages(t: float) -> np.ndarray:
        return dq0_to_abc(v_dq0, omega_e * t)

    def rhs(t: float, i_abc: np.ndarray) -> np.ndarray:
        back_emf = -omega_e * motor.flux_linkage * np.sin(omega_e * t - shifts)
        return (phase_voltages(t) - motor.stator_resistance * i_abc - back_emf) / motor.Ld

    period = 2 * np.pi / omega_e
    t_end = 40 * period  # about 38 stator time constants L/R
    sol = solve_ivp(rhs, (0.0, t_end), np.zeros(3), method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)
    assert sol.success
    t = np.linspace(t_end - period, t_end, 64)
    i_abc = sol.sol(t)
    p_phase = np.sum(phase_voltages(t) * i_abc, axis=0)
    p_model = float(op.electrical_power)
    assert np.max(np.abs(p_phase - p_model)) <= 1e-6 * abs(p_model)
    i_dq0 = abc_to_dq0(i_abc, omega_e * t)
    np.testing.assert_allclose(
        i_dq0.T, np.broadcast_to([0.0, float(op.i_q), 0.0], (t.size, 3)), atol=1e-6 * float(op.i_q)
    )

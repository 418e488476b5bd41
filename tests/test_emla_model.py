"""EMLA operating point: energy balance, efficiency bounds, regeneration, gradients, energy sums."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.emla import (
    EmlaParams,
    electrical_power,
    electrical_power_partials,
    energy_summary,
    load_emla_set,
    operating_point,
    peak_force,
    top_speed,
)
from hiab_sim.emla.pmsm import dq_voltages, electromagnetic_torque
from hiab_sim.errors import InvalidInputError

EMLAS = load_emla_set("paper")
#: An EMLA with samples of its load: (params, f_x [N], v_x [m/s], a_x [m/s^2]).
Loaded = tuple[EmlaParams, np.ndarray, np.ndarray, np.ndarray]


@st.composite
def emla_params(draw: st.DrawFn) -> EmlaParams:
    """XS 031 actuators with perturbed parameters, screw mass and Ld != Lq included."""
    base = draw(st.sampled_from(EMLAS.as_tuple()))
    motor = dataclasses.replace(
        base.motor,
        pole_pairs=draw(st.integers(1, 8)),
        stator_resistance=draw(st.floats(0.0, 2.0, allow_subnormal=False)),
        Ld=draw(st.floats(1e-4, 1e-2)),
        Lq=draw(st.floats(1e-4, 1e-2)),
        rotor_inertia=draw(st.floats(0.0, 0.05)),
        rotor_coulomb_friction=draw(st.floats(0.0, 2.0)),
        friction_smoothing_speed=draw(st.floats(0.01, 10.0)),
    )
    return dataclasses.replace(
        base,
        motor=motor,
        gear_ratio=draw(st.floats(1.0, 10.0, exclude_min=True)),
        screw_lead=draw(st.floats(0.002, 0.025)),
        screw_moving_mass=draw(st.floats(0.0, 200.0)),
        viscous_friction=draw(st.floats(0.0, 1e4)),
    )


@st.composite
def loaded_emlas(draw: st.DrawFn, n: int = 16) -> Loaded:
    """An EMLA of :func:`emla_params` and n drawn (f_x [N], v_x [m/s], a_x [m/s^2]) samples of its load.

    Some samples are at crawl speeds inside the friction smoothing band, one at standstill.
    """
    params = draw(emla_params())
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    f_scale = 1.3 * peak_force(params)
    v_scale = 1.3 * top_speed(params)
    f = rng.uniform(-f_scale, f_scale, n)
    v = rng.uniform(-v_scale, v_scale, n)
    v[: n // 4] *= 3e-3  # crawl speeds, where the regularised friction bends
    v[n // 4] = 0.0
    a = rng.uniform(-3.0, 3.0, n)
    return params, f, v, a


@settings(max_examples=150, deadline=None)
@given(loaded=loaded_emlas())
def test_electrical_power_equals_mechanical_power_plus_losses_to_machine_precision(loaded: Loaded) -> None:
    """P_elec (electrical side) = f v + copper + rotor friction + screw viscous + inertial power."""
    params, f, v, a = loaded
    op = operating_point(params, f, v, a)
    terms = [
        op.mechanical_power,
        op.copper_loss,
        op.rotor_friction_loss,
        op.screw_viscous_loss,
        op.inertial_power,
    ]
    scale = np.sum(np.abs(terms), axis=0) + np.abs(op.electrical_power)
    residual = op.electrical_power - np.sum(terms, axis=0)
    assert np.all(np.abs(residual) <= 8 * np.finfo(float).eps * scale + 1e-300)


@settings(max_examples=150, deadline=None)
@given(
    params=emla_params(),
    i_d=st.floats(-100, 100),
    i_q=st.floats(-100, 100),
    omega=st.floats(-600, 600),
)
def test_dq_power_splits_into_copper_loss_and_air_gap_power_for_any_d_current(
    params: EmlaParams, i_d: float, i_q: float, omega: float
) -> None:
    """3/2 (V_d i_d + V_q i_q) = 3/2 R (i_d^2 + i_q^2) + omega_m tau_m, also with i_d != 0 and Ld != Lq."""
    motor = params.motor
    v_d, v_q = dq_voltages(motor, i_d, i_q, omega)
    p_elec = 1.5 * (v_d * i_d + v_q * i_q)
    expected = 1.5 * motor.stator_resistance * (i_d**2 + i_q**2) + omega * electromagnetic_torque(motor, i_d, i_q)
    assert p_elec == pytest.approx(expected, rel=1e-12, abs=1e-9)


@settings(max_examples=150, deadline=None)
@given(loaded=loaded_emlas())
def test_efficiency_never_exceeds_one_unless_kinetic_energy_is_released(loaded: Loaded) -> None:
    """Efficiency is <= 1 in all four quadrants, in and out of the envelope, wherever a_x v_x >= 0."""
    params, f, v, a = loaded
    a = np.abs(a) * np.sign(v)  # a v >= 0: steady or accelerating
    op = operating_point(params, f, v, a)
    defined = ~np.isnan(op.efficiency)
    assert np.all(op.efficiency[defined] <= 1.0 + 1e-12)
    motoring = op.mechanical_power > 0
    assert np.all(op.electrical_power[motoring] > 0)
    generating = (op.mechanical_power < 0) & (op.electrical_power <= 0)
    returned = np.abs(op.mechanical_power[generating])
    assert np.all(np.abs(op.electrical_power[generating]) <= returned * (1 + 1e-12))


def test_generating_drive_at_crawl_speed_and_high_load_still_draws_more_than_it_receives() -> None:
    """In generating quadrants |P_elec| <= |f v| holds only where the drive actually regenerates.

    Lowering 90 kN at 1 mm/s returns 90 W but costs about 1 kW of copper loss (P_elec > 0).
    """
    op = operating_point(EMLAS.lift, 90e3, -1e-3, 0.0)
    assert op.within_envelope
    assert op.mechanical_power < 0 < op.electrical_power
    assert abs(op.electrical_power) > abs(op.mechanical_power)
    assert op.efficiency < 0  # defined as P_elec / (f v): negative = still drawing


def test_lowering_a_load_at_speed_regenerates_through_the_same_model() -> None:
    """Negative f v at speed gives P_elec < 0 with |P_elec| = |f v| - losses (generating efficiency < 1)."""
    op = operating_point(EMLAS.lift, 60e3, -0.15, 0.0)
    losses = op.copper_loss + op.rotor_friction_loss + op.screw_viscous_loss
    assert op.electrical_power < 0
    assert op.electrical_power == pytest.approx(op.mechanical_power + losses, rel=1e-12)
    assert 0.8 < op.efficiency < 1.0


def test_decelerating_rotor_can_deliver_more_than_the_drive_draws() -> None:
    """While braking (a v < 0) the rotor's kinetic energy joins in, so f v / P_elec may exceed 1."""
    op = operating_point(EMLAS.lift, 2e3, 0.15, -3.0)
    assert op.inertial_power < 0
    assert op.efficiency > 1.0 or np.isnan(op.efficiency)


def test_holding_a_load_at_standstill_costs_exactly_the_copper_loss() -> None:
    """At v = 0, P_elec = 3/2 R i_q^2 > 0 with eta undefined (NaN), where f v / eta would be 0/0."""
    params = EMLAS.lift
    op = operating_point(params, 80e3, 0.0, 0.0)
    i_q = 80e3 / params.transmission_ratio / params.motor.torque_constant
    assert op.electrical_power == pytest.approx(1.5 * params.motor.stator_resistance * i_q**2, rel=1e-14)
    assert np.isnan(op.efficiency)
    assert op.rotor_friction_loss == 0.0


def test_rotor_friction_opposes_motion_and_is_smooth_through_zero_speed() -> None:
    """Friction torque is odd in speed, zero at standstill, ~tau_f beyond a few omega_eps; its power >= 0."""
    params = EMLAS.lift
    eps_v = params.motor.friction_smoothing_speed / params.transmission_ratio
    v = np.array([-20, -1, 0, 1, 20]) * eps_v
    op = operating_point(params, 0.0, v, 0.0)
    friction = op.rotor_friction_loss / np.where(v == 0, 1, op.motor_speed)
    np.testing.assert_allclose(friction, -friction[::-1], atol=1e-15)
    assert friction[2] == 0.0
    assert friction[-1] == pytest.approx(params.motor.rotor_coulomb_friction, rel=1e-12)
    assert np.all(op.rotor_friction_loss >= 0)


def test_lift_operating_point_matches_a_hand_computed_one() -> None:
    """One motoring point (f, v, a) = (50 kN, 0.1 m/s, 0.2 m/s^2) on the lift EMLA, by hand from README "EMLA model".

    The preset's parameters are written out here (and checked against the preset), so the
    expected values do not come from the code under test.
    """
    G, lead, m_sm, b_f = 4.0, 0.010, 0.0, 3000.0  # gear ratio, screw lead [m], screw mass [kg], N s/m
    p, phi, r_s, l_q = 4, 0.12258, 0.268, 2.2e-3  # pole pairs, flux [Wb], ohm, H
    j_m, tau_f, omega_eps = 4.8e-3, 0.2, 1.0  # kg m^2, N m, rad/s
    params = EMLAS.lift
    motor = params.motor
    assert (params.gear_ratio, params.screw_lead, params.screw_moving_mass, params.viscous_friction) == (
        G,
        lead,
        m_sm,
        b_f,
    )
    assert (motor.pole_pairs, motor.flux_linkage, motor.stator_resistance, motor.Lq) == (p, phi, r_s, l_q)
    assert (motor.rotor_inertia, motor.rotor_coulomb_friction, motor.friction_smoothing_speed) == (
        j_m,
        tau_f,
        omega_eps,
    )
    f, v, a = 50e3, 0.1, 0.2
    omega = 2 * np.pi * G * v / lead  # 80 pi rad/s
    tau_m = (
        lead * (f + m_sm * a + b_f * v) / (2 * np.pi * G)
        + j_m * (2 * np.pi * G * a / lead)
        + tau_f * np.tanh(omega / omega_eps)
    )
    i_q = tau_m / (1.5 * p * phi)
    v_d = -p * omega * l_q * i_q
    v_q = r_s * i_q + p * omega * phi
    p_elec = 1.5 * v_q * i_q  # i_d = 0
    # the same numbers, worked out once by hand: omega = 251.327 rad/s, tau_m = 22.6265 N m,
    # i_q = 30.7642 A, V_q = 131.476 V, P = 6067.12 W = 5000 (f v) + 380.47 (copper) + 50.27
    # (friction) + 30 (viscous) + 606.39 (inertial) W
    assert omega == pytest.approx(251.32741, rel=1e-7)
    assert tau_m == pytest.approx(22.626477, rel=1e-7)
    assert p_elec == pytest.approx(6067.1220, rel=1e-7)
    op = operating_point(params, f, v, a)
    assert op.motor_speed == pytest.approx(omega, rel=1e-13)
    assert op.motor_torque == pytest.approx(tau_m, rel=1e-13)
    assert op.i_q == pytest.approx(i_q, rel=1e-13)
    assert op.v_d == pytest.approx(v_d, rel=1e-13)
    assert op.v_q == pytest.approx(v_q, rel=1e-13)
    assert op.electrical_power == pytest.approx(p_elec, rel=1e-13)
    assert op.copper_loss == pytest.approx(1.5 * r_s * i_q**2, rel=1e-13)
    assert op.line_voltage_rms == pytest.approx(np.sqrt(1.5 * (v_d**2 + v_q**2)), rel=1e-13)
    assert op.efficiency == pytest.approx(5000.0 / 6067.1220, rel=1e-7)
    assert electrical_power(params, f, v, a) == pytest.approx(p_elec, rel=1e-13)


def test_electrical_power_equals_the_operating_point_power_elementwise() -> None:
    """electrical_power() (the optimiser's fast path) = operating_point().electrical_power, any shape."""
    f = np.array([[50e3, -30e3], [10e3, -90e3]])
    v = np.array([[0.1, -0.05], [0.18, -0.01]])
    op = operating_point(EMLAS.tilt, f, v, 0.0)
    p = electrical_power(EMLAS.tilt, f, v, 0.0)
    assert p.shape == (2, 2)
    np.testing.assert_array_equal(p, op.electrical_power)


@settings(max_examples=60, deadline=None)
@given(loaded=loaded_emlas())
def test_electrical_power_partials_match_central_finite_differences(loaded: Loaded) -> None:
    """Analytic dP/df, dP/dv, dP/da agree with central differences to 1e-6 relative (+ FD roundoff)."""
    params, f, v, a = loaded
    analytic = electrical_power_partials(params, f, v, a)
    eps_v = params.motor.friction_smoothing_speed / params.transmission_ratio
    steps = (1e-3 * peak_force(params), 1e-4 * eps_v, 1e-3)
    for j, (d_analytic, h) in enumerate(zip(analytic, steps, strict=True)):
        plus = [f, v, a]
        minus = [f, v, a]
        plus[j] = plus[j] + h
        minus[j] = minus[j] - h
        d_fd = (electrical_power(params, *plus) - electrical_power(params, *minus)) / (2 * h)
        roundoff = 100 * np.finfo(float).eps * np.abs(electrical_power(params, f, v, a)).max() / h
        assert np.max(np.abs(d_fd - d_analytic)) <= 1e-6 * np.abs(d_analytic).max() + roundoff, j


def test_energy_summary_credits_regeneration_in_net_but_not_in_drawn_energy() -> None:
    """For P = 1000 sin(t) over one period: net energy 0 J, drawn energy 2000 J (trapezoid rule)."""
    t = np.linspace(0.0, 2 * np.pi, 20001)
    net, drawn = energy_summary(t, 1000.0 * np.sin(t))
    assert abs(net) < 1e-9
    assert drawn == pytest.approx(2000.0, rel=1e-7)
    stacked_net, stacked_drawn = energy_summary(t, np.stack([np.full_like(t, 5.0), -np.ones_like(t)]))
    np.testing.assert_allclose(stacked_net, [10 * np.pi, -2 * np.pi])
    np.testing.assert_allclose(stacked_drawn, [10 * np.pi, 0.0])


def test_energy_summary_rejects_non_increasing_time_and_mismatched_shapes() -> None:
    """Bad time grids raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError, match="time"):
        energy_summary([0.0, 1.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(InvalidInputError, match="electrical_power"):
        energy_summary([0.0, 1.0, 2.0], [1.0, 2.0])

"""Motor thermal limits: RMS torque, copper loss, periodic winding temperature vs an ODE, gradients, bad input."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from thermal_helper import motor_thermal

from hiab_sim.emla.thermal import (
    Duty,
    copper_loss,
    periodic_winding_temperature,
    rms_torque,
    temperature_sensitivity,
)
from hiab_sim.errors import InvalidInputError

FAST = motor_thermal(thermal_resistance=0.5, time_constant=4.0)


def _loss(t: np.ndarray) -> np.ndarray:
    return 200.0 + 150.0 * np.sin(2.0 * np.pi * t / 3.0) ** 2 + 80.0 * t


def test_rms_torque_matches_a_hand_computation() -> None:
    """Samples (3, 4, 0) N m at t = 0, 1, 2 s with a 3 s rest: tau_rms^2 = (12.5 + 8) / 5."""
    rms, _ = rms_torque([0.0, 1.0, 2.0], [3.0, 4.0, 0.0], Duty(2.0, 3.0))
    assert rms == pytest.approx(math.sqrt(20.5 / 5.0), rel=1e-15)


def test_rms_torque_of_a_sine_with_rest_matches_the_analytic_value() -> None:
    """A sin over the cycle and an equal rest: tau_rms = A / sqrt(2) * sqrt(T / (T + T_rest))."""
    t = np.linspace(0.0, 6.25, 20001)
    rms, _ = rms_torque(t, 20.0 * np.sin(2.0 * np.pi * t / 6.25), Duty(6.25, 6.25))
    assert rms == pytest.approx(20.0 / math.sqrt(2.0) * math.sqrt(0.5), rel=1e-7)


def test_rms_torque_gradient_matches_finite_differences() -> None:
    """The RMS torque gradient d tau_rms / d tau_k agrees with central differences."""
    rng = np.random.default_rng(3)
    t = np.sort(np.r_[0.0, rng.uniform(0, 2, 10), 2.0])
    tau = rng.normal(0, 10, t.size)
    duty = Duty(2.0, 1.5)
    _, grad = rms_torque(t, tau, duty)
    h = 1e-6
    for k in range(t.size):
        up, down = tau.copy(), tau.copy()
        up[k] += h
        down[k] -= h
        fd = (rms_torque(t, up, duty)[0] - rms_torque(t, down, duty)[0]) / (2 * h)
        assert grad[k] == pytest.approx(fd, rel=1e-7, abs=1e-10)


def test_cycles_per_hour_set_the_rest_time() -> None:
    """60 cycles of 6.25 s an hour leave 53.75 s of rest per cycle; more than 3600/T is rejected."""
    assert Duty.from_cycles_per_hour(6.25, 60.0).rest_time == pytest.approx(53.75, rel=1e-15)
    with pytest.raises(InvalidInputError, match=r"duty\.cycles_per_hour"):
        Duty.from_cycles_per_hour(6.25, 600.0)


def test_copper_loss_is_three_halves_r_i_squared_with_its_derivative() -> None:
    """P_cu = 3/2 R_s i_q^2 with i_q = tau / K_t; its derivative agrees with finite differences."""
    p, d = copper_loss(0.268, 0.735, np.array([14.0, -5.0]))
    i_q = np.array([14.0, -5.0]) / 0.735
    assert p == pytest.approx(1.5 * 0.268 * i_q**2, rel=1e-15)
    fd = (copper_loss(0.268, 0.735, np.array([14.0, -5.0]) + 1e-6)[0] - p) / 1e-6
    assert d == pytest.approx(fd, rel=1e-5)


def test_constant_loss_without_rest_gives_the_steady_temperature() -> None:
    """Continuous constant loss P: T_winding = T_amb + R_th P at every sample."""
    t = np.linspace(0.0, 3.0, 31)
    result = periodic_winding_temperature(t, np.full(31, 200.0), FAST, Duty(3.0, 0.0))
    assert result.temperature == pytest.approx(40.0 + 0.5 * 200.0, rel=1e-13)


def test_periodic_temperature_matches_an_ode_integration_over_repeated_cycles() -> None:
    """Integrating the winding ODE over 40 duty periods from ambient lands on the closed-form periodic state."""
    t = np.linspace(0.0, 3.0, 61)
    loss = _loss(t)
    duty = Duty(3.0, 2.0)
    closed = periodic_winding_temperature(t, loss, FAST, duty)

    def rhs(time: float, theta: np.ndarray) -> np.ndarray:
        return (FAST.thermal_resistance * np.interp(time, t, loss) - theta) / FAST.time_constant

    def rest(time: float, theta: np.ndarray) -> np.ndarray:
        return -theta / FAST.time_constant

    theta = np.zeros(1)
    for _ in range(40):  # cycle (loss interpolated between samples), then rest (no loss)
        cycle = solve_ivp(rhs, (0.0, duty.cycle_time), theta, rtol=1e-12, atol=1e-12, t_eval=t)
        theta = solve_ivp(rest, (0.0, duty.rest_time), cycle.y[:, -1], rtol=1e-12, atol=1e-12).y[:, -1]
    ode = 40.0 + cycle.y[0]
    assert closed.temperature == pytest.approx(ode, abs=1e-7)
    assert closed.peak == pytest.approx(ode.max(), abs=1e-7)


def test_temperature_gradients_match_finite_differences() -> None:
    """Peak and per-sample temperature gradients agree with central differences."""
    t = np.linspace(0.0, 3.0, 16)
    loss = _loss(t)
    duty = Duty(3.0, 1.0)
    base = periodic_winding_temperature(t, loss, FAST, duty)
    sens = temperature_sensitivity(t, FAST, duty, 4)
    h = 1e-4
    for k in range(t.size):
        up, down = loss.copy(), loss.copy()
        up[k] += h
        down[k] -= h
        hi = periodic_winding_temperature(t, up, FAST, duty)
        lo = periodic_winding_temperature(t, down, FAST, duty)
        assert base.d_peak_d_loss[k] == pytest.approx((hi.peak - lo.peak) / (2 * h), rel=1e-6, abs=1e-10)
        assert sens[k] == pytest.approx((hi.temperature[4] - lo.temperature[4]) / (2 * h), rel=1e-6, abs=1e-10)


@pytest.mark.parametrize(
    ("field", "changes"),
    [
        ("lift.thermal.thermal_resistance", {"thermal_resistance": -0.5}),
        ("lift.thermal.time_constant", {"time_constant": 0.0}),
        ("lift.thermal.continuous_torque", {"continuous_torque": float("nan")}),
        ("lift.thermal.max_winding_temperature", {"max_winding_temperature": 30.0}),
    ],
)
def test_bad_thermal_parameters_name_the_field(field: str, changes: dict[str, float]) -> None:
    """Negative R_th, zero time constant, NaN torque, T_max <= T_amb are rejected by name."""
    valid = motor_thermal(thermal_resistance=0.5, time_constant=1800.0, label="lift.thermal")
    with pytest.raises(InvalidInputError, match=re.escape(field)):
        dataclasses.replace(valid, **changes)


def test_a_duty_with_no_time_is_rejected() -> None:
    """A zero cycle time or negative rest is rejected, and the grid must span the cycle."""
    with pytest.raises(InvalidInputError, match=r"duty\.cycle_time"):
        Duty(0.0, 10.0)
    with pytest.raises(InvalidInputError, match=r"duty\.rest_time"):
        Duty(5.0, -1.0)
    with pytest.raises(InvalidInputError, match=r"duty\.cycle_time"):
        rms_torque([0.0, 1.0], [1.0, 1.0], Duty(2.0))


def test_preset_thermal_resistance_heats_the_winding_to_its_limit_at_continuous_torque() -> None:
    """The derived R_th: copper loss at the continuous torque, held, brings the winding to T_max (1e-4)."""
    from hiab_sim.emla import load_emla_set

    for params in load_emla_set("paper"):
        th = params.thermal
        assert th is not None and th.label == f"{params.name}.thermal"
        loss, _ = copper_loss(params.motor.stator_resistance, params.motor.torque_constant, th.continuous_torque)
        rise = th.max_winding_temperature - th.ambient_temperature
        assert float(loss) * th.thermal_resistance == pytest.approx(rise, rel=1e-4)
        assert params.source_of("thermal.thermal_resistance").startswith("derived")


def test_negative_thermal_resistance_in_the_emla_file_names_the_field() -> None:
    """An override with R_th < 0 is rejected as tilt.thermal.thermal_resistance; a missing key is a ConfigError."""
    import yaml

    from hiab_sim.emla.config import emla_set_from_mapping
    from hiab_sim.errors import ConfigError
    from hiab_sim.resources import shipped

    doc = yaml.safe_load(shipped("emla", "paper").read_text())
    doc["actuators"]["tilt"]["thermal"] = {"thermal_resistance": -0.5}
    with pytest.raises(InvalidInputError, match=re.escape("tilt.thermal.thermal_resistance")):
        emla_set_from_mapping(doc)
    doc = yaml.safe_load(shipped("emla", "paper").read_text())
    del doc["thermal"]["time_constant"]
    with pytest.raises(ConfigError, match="time_constant"):
        emla_set_from_mapping(doc)

"""Hot windings: the coupled periodic steady state against a time-stepped ODE, its gradients, runaway, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from thermal_helper import motor_thermal

from hiab_sim.emla.electrothermal import (
    FIXED_POINT_TOLERANCE_K,
    WindingResistance,
    coupled_winding_temperature,
)
from hiab_sim.emla.thermal import Duty, periodic_winding_temperature
from hiab_sim.errors import InvalidInputError

THERMAL = motor_thermal(thermal_resistance=0.4, time_constant=20.0)
COPPER = WindingResistance(reference_temperature=20.0, temperature_coefficient=0.00393, insulation_limit=155.0)
R_REF, K_T = 0.268, 0.7355  # ohm, N m/A


def _current(t: np.ndarray | float) -> np.ndarray:
    """A q-axis current history [A] written for the test (lifting, then holding)."""
    return 18.0 + 12.0 * np.sin(2.0 * np.pi * np.asarray(t) / 2.0) + 4.0 * np.cos(6.0 * np.pi * np.asarray(t) / 2.0)


def _ode_periodic(duty: Duty, rest_current: float, substeps: int = 8000) -> tuple[np.ndarray, float, float]:
    """Independent model: RK4 on dT/dt = (R_th P(T, t) - (T - T_amb)) / tau_th with P = 3/2 R_ref (1 + a (T - 20)) i^2.

    The periodic state is found by shooting: the one-period map is affine in T(0), so two runs from
    two starts give its fixed point. Returns (T at the cycle's sample times, rest copper energy [J],
    and the cycle's sample step used).
    """
    tau, r, t_amb = THERMAL.time_constant, THERMAL.thermal_resistance, THERMAL.ambient_temperature

    def power(temp: np.ndarray, i: float) -> np.ndarray:
        return 1.5 * R_REF * (1.0 + 0.00393 * (temp - 20.0)) * i * i

    def rhs(temp: np.ndarray, t: float | None, i_rest: float) -> np.ndarray:
        i = float(_current(t)) if t is not None else i_rest
        return (r * power(temp, i) - (temp - t_amb)) / tau

    def run(start: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        temp = start.copy()
        h = duty.cycle_time / substeps
        samples = [temp.copy()]
        for n in range(substeps):
            t0 = n * h
            k1 = rhs(temp, t0, 0.0)
            k2 = rhs(temp + 0.5 * h * k1, t0 + 0.5 * h, 0.0)
            k3 = rhs(temp + 0.5 * h * k2, t0 + 0.5 * h, 0.0)
            k4 = rhs(temp + h * k3, t0 + h, 0.0)
            temp = temp + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
            samples.append(temp.copy())
        hr = duty.rest_time / substeps
        energy = np.zeros_like(temp)
        for _ in range(substeps):  # rest: constant current, copper energy by Simpson on each step
            k1 = rhs(temp, None, rest_current)
            k2 = rhs(temp + 0.5 * hr * k1, None, rest_current)
            k3 = rhs(temp + 0.5 * hr * k2, None, rest_current)
            k4 = rhs(temp + hr * k3, None, rest_current)
            new = temp + hr / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
            mid = 0.5 * (temp + new) + hr / 8.0 * (k1 - rhs(new, None, rest_current))  # cubic Hermite midpoint
            energy += hr / 6.0 * (power(temp, rest_current) + 4 * power(mid, rest_current) + power(new, rest_current))
            temp = new
        return np.array(samples), temp, energy

    starts = np.array([40.0, 120.0])
    samples, end, energy = run(starts)
    slope = (end[1] - end[0]) / (starts[1] - starts[0])
    fixed = (end[0] - slope * starts[0]) / (1.0 - slope)
    lam = (fixed - starts[0]) / (starts[1] - starts[0])
    cycle = samples[:, 0] + lam * (samples[:, 1] - samples[:, 0])
    rest_energy = energy[0] + lam * (energy[1] - energy[0])
    return cycle, float(rest_energy), duty.cycle_time / substeps


@pytest.mark.parametrize("rest_current", [0.0, 25.0])
def test_hot_winding_energy_matches_a_time_stepped_coupled_model(rest_current: float) -> None:
    """Cycle + rest copper energy at the coupled periodic temperatures agrees with an RK4 model to 1e-6."""
    duty = Duty(2.0, 3.0)
    step = 8
    tt, rest_energy_ode, _ = _ode_periodic(duty, rest_current)
    temp_ode = tt[::step]
    t = np.linspace(0.0, 2.0, temp_ode.size)
    c = 1.5 * R_REF * _current(t) ** 2
    rest_c = 1.5 * R_REF * rest_current**2
    state = coupled_winding_temperature(t, c, THERMAL, COPPER, duty, rest_c)
    w = np.full(t.size, t[1] - t[0])
    w[[0, -1]] *= 0.5
    energy_ode = float(w @ (c * (1.0 + 0.00393 * (temp_ode - 20.0)))) + rest_energy_ode
    energy = float(w @ state.hot_loss) + state.rest_energy
    assert energy == pytest.approx(energy_ode, rel=1e-6)
    assert state.temperature == pytest.approx(temp_ode, abs=1e-4)
    assert state.resistance_factor.max() > 1.2  # a strong coupling: R_s 1.2 x its 20 deg C value
    assert state.fixed_point_change_K < FIXED_POINT_TOLERANCE_K


def test_without_temperature_coefficient_the_existing_winding_model_is_reproduced() -> None:
    """Alpha = 0 and T_ref = T_amb: the coupled state equals periodic_winding_temperature of the cold losses."""
    t = np.linspace(0.0, 2.0, 201)
    c = 1.5 * R_REF * _current(t) ** 2
    duty = Duty(2.0, 3.0)
    flat = WindingResistance(40.0, 0.0, 155.0)
    state = coupled_winding_temperature(t, c, THERMAL, flat, duty)
    ref = periodic_winding_temperature(t, c, THERMAL, duty)
    assert state.temperature == pytest.approx(ref.temperature, rel=1e-13)
    assert state.peak_index == ref.peak_index


def test_picard_iteration_of_the_existing_model_converges_to_the_fixed_point() -> None:
    """Temperature -> losses -> temperature with the cold model, iterated under 0.1 K, lands on the coupled state."""
    t = np.linspace(0.0, 2.0, 201)
    c = 1.5 * R_REF * _current(t) ** 2
    duty = Duty(2.0, 3.0)
    temp = np.full(t.size, THERMAL.ambient_temperature)
    for _ in range(200):
        loss = c * (1.0 + COPPER.temperature_coefficient * (temp - COPPER.reference_temperature))
        new = periodic_winding_temperature(t, loss, THERMAL, duty).temperature
        change = float(np.max(np.abs(new - temp)))
        temp = new
        if change < 1e-10:
            break
    state = coupled_winding_temperature(t, c, THERMAL, COPPER, duty)
    assert state.temperature == pytest.approx(temp, abs=1e-8)
    assert state.fixed_point_change_K < 1e-9


@pytest.mark.parametrize("rest_current", [0.0, 20.0])
def test_hot_energy_gradient_matches_finite_differences(rest_current: float) -> None:
    """d(sum_k y_k P_k + z E_rest)/d(c, c_r) by the adjoint agrees with central differences."""
    rng = np.random.default_rng(7)
    t = np.sort(np.r_[0.0, rng.uniform(0.0, 2.0, 14), 2.0])
    c = 1.5 * R_REF * _current(t) ** 2
    c_r = 1.5 * R_REF * rest_current**2
    duty = Duty(2.0, 3.0)
    y = rng.uniform(0.1, 1.0, t.size)
    z = 0.7

    def objective(cc: np.ndarray, cr: float) -> float:
        s = coupled_winding_temperature(t, cc, THERMAL, COPPER, duty, cr)
        return float(y @ s.hot_loss) + z * s.rest_energy

    d_c, d_cr = coupled_winding_temperature(t, c, THERMAL, COPPER, duty, c_r).loss_gradient(y, z)
    h = 1e-3
    for k in range(t.size):
        up, down = c.copy(), c.copy()
        up[k] += h
        down[k] -= h
        fd = (objective(up, c_r) - objective(down, c_r)) / (2 * h)
        assert d_c[k] == pytest.approx(fd, rel=1e-7, abs=1e-9)
    if c_r > 0:
        fd_r = (objective(c, c_r + h) - objective(c, c_r - h)) / (2 * h)
    else:  # the rest loss cannot be negative: second-order one-sided difference
        fd_r = (-3 * objective(c, c_r) + 4 * objective(c, c_r + h) - objective(c, c_r + 2 * h)) / (2 * h)
    assert d_cr == pytest.approx(fd_r, rel=1e-7, abs=1e-9)


def test_peak_temperature_gradient_matches_finite_differences() -> None:
    """D T_peak / d(c, c_r) by the adjoint agrees with central differences (peak index held)."""
    t = np.linspace(0.0, 2.0, 21)
    c = 1.5 * R_REF * _current(t) ** 2
    duty = Duty(2.0, 3.0)
    c_r = 50.0
    base = coupled_winding_temperature(t, c, THERMAL, COPPER, duty, c_r)
    j = base.peak_index
    d_c, d_cr = base.temperature_gradient(j)
    h = 1e-3
    for k in range(t.size):
        up, down = c.copy(), c.copy()
        up[k] += h
        down[k] -= h
        fd = (
            coupled_winding_temperature(t, up, THERMAL, COPPER, duty, c_r).temperature[j]
            - coupled_winding_temperature(t, down, THERMAL, COPPER, duty, c_r).temperature[j]
        ) / (2 * h)
        assert d_c[k] == pytest.approx(fd, rel=1e-7, abs=1e-10)
    fd_r = (
        coupled_winding_temperature(t, c, THERMAL, COPPER, duty, c_r + h).temperature[j]
        - coupled_winding_temperature(t, c, THERMAL, COPPER, duty, c_r - h).temperature[j]
    ) / (2 * h)
    assert d_cr == pytest.approx(fd_r, rel=1e-7)


def test_loss_beyond_the_cooling_runs_away() -> None:
    """Alpha R_th c >= 1 on average: the resistance grows faster than the cooling, so no fixed point exists."""
    t = np.linspace(0.0, 2.0, 21)
    c = np.full(t.size, 1.2 / (COPPER.temperature_coefficient * THERMAL.thermal_resistance))
    state = coupled_winding_temperature(t, c, THERMAL, COPPER, Duty(2.0, 0.0))
    assert state.runaway and math.isinf(state.peak)
    held = coupled_winding_temperature(t, np.zeros(t.size), THERMAL, COPPER, Duty(2.0, 3.0), float(c[0]))
    assert held.runaway


def test_a_fixed_point_above_the_insulation_limit_counts_as_runaway() -> None:
    """A stable fixed point at about 195 deg C lies above class F's 155 deg C: reported as runaway."""
    t = np.linspace(0.0, 2.0, 21)
    c = np.full(t.size, 250.0)
    state = coupled_winding_temperature(t, c, THERMAL, COPPER, Duty(2.0, 0.0))
    assert state.poincare_slope < 1.0
    assert state.peak > 155.0 and state.runaway
    # steady state of dT/dt = 0: theta = R_th c (beta + alpha theta)
    beta = 1.0 + 0.00393 * (40.0 - 20.0)
    theta = 0.4 * 250.0 * beta / (1.0 - 0.4 * 250.0 * 0.00393)
    assert state.peak == pytest.approx(40.0 + theta, rel=1e-12)


def test_winding_resistance_rejects_bad_values() -> None:
    """A negative coefficient or an insulation limit below the reference temperature is rejected."""
    with pytest.raises(InvalidInputError, match=r"winding_resistance\.temperature_coefficient"):
        WindingResistance(20.0, -0.001, 155.0)
    with pytest.raises(InvalidInputError, match=r"winding_resistance\.insulation_limit"):
        WindingResistance(20.0, 0.00393, 10.0)
    with pytest.raises(InvalidInputError, match="cold_loss"):
        coupled_winding_temperature([0.0, 1.0], [1.0], THERMAL, COPPER, Duty(1.0, 0.0))

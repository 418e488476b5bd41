"""Battery energy on a shared DC bus: hand case, convergence of the smoothing, gradient, bad input."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from hiab_sim.emla.battery import BatteryParams, battery_energy, trapezoid_weights
from hiab_sim.errors import InvalidInputError


def _powers(t: np.ndarray) -> np.ndarray:
    """Three drives, motoring and regenerating at different times (W)."""
    return np.column_stack(
        [
            1500.0 * np.sin(2.0 * np.pi * t / 3.0) + 300.0,
            -800.0 * np.cos(2.0 * np.pi * t / 2.0),
            200.0 * np.sin(2.0 * np.pi * t / 1.5 + 0.3) - 50.0,
        ]
    )


def test_regeneration_of_one_drive_feeds_another_before_the_battery() -> None:
    """Hand case: 1000 W motoring and 600 W regenerating share the bus; the battery supplies the rest."""
    params = BatteryParams(inverter_efficiency=0.9, discharge_efficiency=0.8, charge_efficiency=0.5)
    t = np.array([0.0, 1.0, 2.0])
    p = np.tile([1000.0, -600.0, 0.0], (3, 1))
    result = battery_energy(t, p, params)
    bus = 1000.0 / 0.9 - 600.0 * 0.9  # 571.1 W on the bus
    assert result.energy == pytest.approx(2.0 * bus / 0.8, rel=1e-14)
    assert result.drawn_energy == pytest.approx([2000.0, 0.0, 0.0], rel=1e-14)
    # A regenerating bus charges the battery with eta_ch.
    charging = battery_energy(t, np.tile([100.0, -600.0, 0.0], (3, 1)), params)
    assert charging.energy == pytest.approx(2.0 * (100.0 / 0.9 - 600.0 * 0.9) * 0.5, rel=1e-14)


def test_ideal_efficiencies_give_the_net_electrical_energy() -> None:
    """With every efficiency 1 the battery energy is the trapezoid of sum_i P_i, smoothed or not."""
    params = BatteryParams(1.0, 1.0, 1.0, smoothing_power=50.0)
    t = np.linspace(0.0, 3.0, 301)
    p = _powers(t)
    total = p.sum(axis=1)
    reference = float(np.sum(0.5 * (total[1:] + total[:-1]) * np.diff(t)))
    for smooth in (False, True):
        assert battery_energy(t, p, params, smooth=smooth).energy == pytest.approx(reference, rel=1e-13)


def test_exact_energy_converges_to_the_integral_of_the_continuous_power() -> None:
    """The exact (kinked) trapezoid on a fine grid matches adaptive quadrature of the continuous-time model."""
    params = BatteryParams(0.95, 0.9, 0.85)

    def battery_power(time: float) -> float:
        p = _powers(np.array([time]))[0]
        dc = np.where(p > 0, p / 0.95, p * 0.95).sum()
        return float(dc / 0.9 if dc > 0 else dc * 0.85)

    reference, _ = quad(battery_power, 0.0, 3.0, limit=500, epsabs=1e-9)
    t = np.linspace(0.0, 3.0, 30001)
    assert battery_energy(t, _powers(t), params).energy == pytest.approx(reference, rel=1e-6)


def test_smooth_energy_converges_to_the_exact_energy_within_the_stated_bound() -> None:
    """0 <= E_smooth - E_exact <= eps ln2 (...) T, and the gap shrinks in proportion to eps."""
    t = np.linspace(0.0, 3.0, 3001)
    p = _powers(t)
    exact = battery_energy(t, p, BatteryParams(0.95, 0.9, 0.85)).energy
    gaps = []
    for eps in (100.0, 10.0, 1.0, 0.1, 0.01):
        params = BatteryParams(0.95, 0.9, 0.85, smoothing_power=eps)
        gap = battery_energy(t, p, params, smooth=True).energy - exact
        assert 0.0 <= gap <= params.smoothing_bound(3, 3.0)
        gaps.append(gap)
    assert gaps[-1] < 1e-3 * gaps[0]


@settings(max_examples=30, deadline=None)
@given(
    eta=st.tuples(st.floats(0.5, 1.0), st.floats(0.5, 1.0), st.floats(0.5, 1.0)),
    eps=st.floats(1.0, 200.0),
    seed=st.integers(0, 2**31),
)
def test_smooth_energy_gradient_matches_finite_differences(
    eta: tuple[float, float, float], eps: float, seed: int
) -> None:
    """dE/dP of the smooth energy agrees with central differences at random samples."""
    params = BatteryParams(*eta, smoothing_power=eps)
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 2.0, 12))
    t[0], t[-1] = 0.0, 2.0
    p = rng.normal(0.0, 300.0, (12, 3))
    grad = battery_energy(t, p, params, smooth=True).gradient
    h = 1e-3
    for k, i in zip(rng.integers(0, 12, 6), rng.integers(0, 3, 6), strict=True):
        up, down = p.copy(), p.copy()
        up[k, i] += h
        down[k, i] -= h
        fd = battery_energy(t, up, params, smooth=True).energy - battery_energy(t, down, params, smooth=True).energy
        assert grad[k, i] == pytest.approx(fd / (2 * h), rel=1e-6, abs=1e-9)


def test_trapezoid_weights_integrate_a_linear_function_exactly_on_an_uneven_grid() -> None:
    """The weights integrate a linear function exactly on an uneven grid."""
    t = np.array([0.0, 0.1, 0.5, 0.6, 2.0])
    assert trapezoid_weights(t) @ (3.0 * t + 1.0) == pytest.approx(1.5 * 4.0 + 2.0, rel=1e-14)


@pytest.mark.parametrize(
    ("field", "kwargs"),
    [
        ("battery.inverter_efficiency", {"inverter_efficiency": 0.0}),
        ("battery.discharge_efficiency", {"discharge_efficiency": 1.2}),
        ("battery.charge_efficiency", {"charge_efficiency": -0.5}),
        ("battery.smoothing_power", {"smoothing_power": 0.0}),
    ],
)
def test_out_of_range_battery_parameters_name_the_field(field: str, kwargs: dict[str, float]) -> None:
    """Efficiencies outside (0, 1] and a non-positive smoothing width are rejected by name."""
    with pytest.raises(InvalidInputError, match=re.escape(field)):
        BatteryParams(**kwargs)


def test_power_of_the_wrong_shape_is_rejected() -> None:
    """Power must be (K, n) with K the number of time samples."""
    with pytest.raises(InvalidInputError, match="power"):
        battery_energy(np.linspace(0, 1, 5), np.zeros((4, 3)), BatteryParams())


def test_bus_and_no_regeneration_figures_differ_by_the_credit_passed_between_drives() -> None:
    """Hand case: 1000 W and -600 W drives; the bus figure credits the 600 W, the no-regeneration one does not."""
    from hiab_sim.emla.battery import rest_battery_energy

    params = BatteryParams(inverter_efficiency=0.9, discharge_efficiency=0.8, charge_efficiency=0.5)
    t = np.array([0.0, 1.0, 2.0])
    result = battery_energy(t, np.tile([1000.0, -600.0, 0.0], (3, 1)), params)
    assert result.dc_bus_drawn_energy == pytest.approx(2.0 * (1000.0 / 0.9 - 600.0 * 0.9), rel=1e-14)
    assert result.no_regeneration_energy_at_battery == pytest.approx(2.0 * 1000.0 / 0.9 / 0.8, rel=1e-14)
    energy, gain = rest_battery_energy([100.0, 50.0, 0.0], params)
    assert energy == pytest.approx(150.0 / (0.9 * 0.8), rel=1e-14) and gain == pytest.approx(1 / 0.72)
    with pytest.raises(InvalidInputError, match="rest_energy"):
        rest_battery_energy([-1.0, 0.0, 0.0], params)

"""EMLA envelope: peak torque, rated speed and voltage limits as smooth margins with exact gradients."""

from __future__ import annotations

import numpy as np
import pytest

from hiab_sim.emla import (
    ENVELOPE_LIMIT_NAMES,
    envelope_margin_partials,
    envelope_margins,
    line_voltage_rms,
    load_emla_set,
    operating_point,
    peak_force,
    top_speed,
    within_envelope,
)

EMLAS = load_emla_set("paper")


def _random_samples(params, n: int = 400, seed: int = 5):  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(seed)
    f = rng.uniform(-1.3, 1.3, n) * peak_force(params)
    v = rng.uniform(-1.3, 1.3, n) * top_speed(params)
    v[:50] *= 3e-3
    a = rng.uniform(-3.0, 3.0, n)
    return f, v, a


def test_margins_have_one_row_per_named_limit_and_are_order_one_inside() -> None:
    """Shape (3, *shape); at rest every margin is 1; feasible points have margins in [0, 1]."""
    params = EMLAS.lift
    f, v, a = _random_samples(params)
    g = envelope_margins(params, f.reshape(20, 20), v.reshape(20, 20), a.reshape(20, 20))
    assert ENVELOPE_LIMIT_NAMES == ("peak_torque", "rated_speed", "voltage")
    assert g.shape == (3, 20, 20)
    np.testing.assert_array_equal(envelope_margins(params, 0.0, 0.0, 0.0), [1.0, 1.0, 1.0])
    feasible = np.all(g >= 0, axis=0)
    assert feasible.any() and (~feasible).any()
    assert np.all((g[:, feasible] >= 0) & (g[:, feasible] <= 1))


@pytest.mark.parametrize("params", EMLAS.as_tuple(), ids=lambda p: p.name)
def test_margins_vanish_exactly_on_each_physical_limit(params) -> None:  # type: ignore[no-untyped-def]
    """Torque margin is 0 at |tau_m| = tau_peak, speed margin at top speed, voltage margin at V_LL = V_max."""
    k = params.transmission_ratio
    g = envelope_margins(params, np.array([k * params.motor.peak_torque, -k * params.motor.peak_torque]), 0.0, 0.0)
    np.testing.assert_allclose(g[0], 0.0, atol=1e-12)
    g = envelope_margins(params, 0.0, np.array([top_speed(params), -top_speed(params)]), 0.0)
    np.testing.assert_allclose(g[1], 0.0, atol=1e-12)
    f, v = 0.6 * peak_force(params), 0.95 * top_speed(params)
    op = operating_point(params, f, v, 0.0)
    ratio = line_voltage_rms(op.v_d, op.v_q) / params.motor.max_line_voltage_rms
    assert op.margins[2] == pytest.approx(1 - ratio**2, rel=1e-12)


@pytest.mark.parametrize("params", EMLAS.as_tuple(), ids=lambda p: p.name)
def test_points_beyond_a_limit_are_flagged(params) -> None:  # type: ignore[no-untyped-def]
    """Over peak force, over top speed, or peak force at top speed (voltage) lie outside the envelope."""
    f_peak, v_top = peak_force(params), top_speed(params)
    assert within_envelope(params, 0.0, 0.999 * v_top, 0.0)  # no-load top speed is feasible
    assert not within_envelope(params, 1.02 * f_peak, 0.05 * v_top, 0.0)
    assert not within_envelope(params, 0.0, 1.01 * v_top, 0.0)
    op = operating_point(params, 0.95 * f_peak, 0.98 * v_top, 0.0)
    assert op.margins[0] > 0 and op.margins[1] > 0 and op.margins[2] < 0  # only the voltage limit bites
    assert not op.within_envelope


@pytest.mark.parametrize("params", EMLAS.as_tuple(), ids=lambda p: p.name)
def test_margin_partials_match_central_finite_differences(params) -> None:  # type: ignore[no-untyped-def]
    """Analytic dg/df, dg/dv, dg/da agree with central differences (1e-6 relative), crawl speeds too."""
    f, v, a = _random_samples(params)
    analytic = envelope_margin_partials(params, f, v, a)
    eps_v = params.motor.friction_smoothing_speed / params.transmission_ratio
    steps = (1e-3 * peak_force(params), 1e-4 * eps_v, 1e-3)
    for j, (d_analytic, h) in enumerate(zip(analytic, steps, strict=True)):
        plus, minus = [f, v, a], [f, v, a]
        plus[j] = plus[j] + h
        minus[j] = minus[j] - h
        d_fd = (envelope_margins(params, *plus) - envelope_margins(params, *minus)) / (2 * h)
        assert d_analytic.shape == (3, f.size)
        roundoff = 100 * np.finfo(float).eps * 2.0 / h
        for row in range(3):
            error = np.max(np.abs(d_fd[row] - d_analytic[row]))
            assert error <= 1e-6 * np.abs(d_analytic[row]).max() + roundoff, (j, row)

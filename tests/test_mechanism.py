"""Closed-chain trigonometry: round trips, triangle property, velocity ratios vs finite differences."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ChainLengths
from hiab_sim.crane.loader import load_crane

CRANE = load_crane("xs031")
CHAINS = {chain.name: chain for chain in CRANE.chains}
fractions = st.floats(min_value=0.0, max_value=1.0)
chain_names = st.sampled_from(sorted(CHAINS))


def _working_theta(name: str, fraction: float) -> float:
    low, high = CHAINS[name].joint_range
    return low + fraction * (high - low)


@settings(max_examples=200, deadline=None)
@given(chain_names, fractions)
def test_theta_to_stroke_to_theta_round_trip(name: str, fraction: float) -> None:
    """Theta -> x -> theta returns theta to 1e-12 rad over the working range."""
    chain = CHAINS[name]
    theta = _working_theta(name, fraction)
    x = mechanism.joint_to_stroke(chain, chain.default_lengths, theta)
    assert abs(mechanism.stroke_to_joint(chain, chain.default_lengths, x) - theta) <= 1e-12


@settings(max_examples=200, deadline=None)
@given(chain_names, st.floats(min_value=0.001, max_value=0.999))
def test_stroke_to_theta_to_stroke_round_trip(name: str, fraction: float) -> None:
    """X -> theta -> x returns x to 1e-12 m inside the usable stroke."""
    chain = CHAINS[name]
    x_min, x_max = mechanism.stroke_bounds(chain, chain.default_lengths)
    x = x_min + fraction * (x_max - x_min)
    theta = mechanism.stroke_to_joint(chain, chain.default_lengths, x)
    assert abs(mechanism.joint_to_stroke(chain, chain.default_lengths, theta) - x) <= 1e-12


@settings(max_examples=200, deadline=None)
@given(st.floats(0.3, 2.0), st.floats(0.2, 1.0), st.floats(0.5, 1.5), st.floats(0.01, 0.99))
def test_internal_angles_satisfy_triangle_property(L: float, L1: float, x0: float, fraction: float) -> None:
    """Q + q1 + q2 = -pi (eq. triangle, const_l) for any non-degenerate triangle."""
    s_min, s_max = abs(L - L1), L + L1
    s = s_min + fraction * (s_max - s_min)
    q, q1, q2 = mechanism.triangle_angles(s - x0, L, L1, x0)
    assert abs(q + q1 + q2 + np.pi) <= 1e-12
    assert -np.pi < q < 0 and -np.pi < q1 < 0 and -np.pi < q2 < 0


def _sample_strokes(chain_name: str) -> np.ndarray:
    chain = CHAINS[chain_name]
    x_min, x_max = mechanism.stroke_bounds(chain, chain.default_lengths)
    return np.linspace(x_min + 0.02, x_max - 0.02, 41)


def _constructed_angles(s: np.ndarray, L: float, L1: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, q1, q2) of the triangle built from its vertices, independent of the module's law-of-cosines form.

    Boom hinge {B1} at the origin, cylinder base {Bc} at (L, 0), rod end {Tc} where the circles of
    radius L1 about {B1} and s about {Bc} meet (upper half plane). Each internal angle is minus the
    angle between the two edges at its vertex, measured with atan2(|cross|, dot).
    """
    tx = (L**2 + L1**2 - s**2) / (2.0 * L)
    b1, bc = np.zeros((len(s), 2)), np.tile([L, 0.0], (len(s), 1))
    tc = np.column_stack([tx, np.sqrt(L1**2 - tx**2)])

    def angle(at: np.ndarray, p: np.ndarray, r: np.ndarray) -> np.ndarray:
        u, v = p - at, r - at
        return np.arctan2(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]), np.sum(u * v, axis=1))

    return -angle(b1, bc, tc), -angle(bc, b1, tc), -angle(tc, b1, bc)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_triangle_angles_match_the_constructed_triangle(name: str) -> None:
    """Q, q1, q2 (eq. qus) equal the angles of the triangle drawn from its side lengths, to 1e-12 rad."""
    chain, xi = CHAINS[name], CHAINS[name].default_lengths
    x = _sample_strokes(name)
    for ours, built in zip(
        mechanism.triangle_angles(x, xi.L, chain.L1, xi.x0), _constructed_angles(x + xi.x0, xi.L, chain.L1), strict=True
    ):
        np.testing.assert_allclose(ours, built, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_velocity_ratios_match_central_differences(name: str) -> None:
    """k1, k2, k3 (eq. k1_3) equal d(q, q1, q2)/dx of the constructed triangle by central differences."""
    chain, xi = CHAINS[name], CHAINS[name].default_lengths
    x, h = _sample_strokes(name), 1e-6
    plus = _constructed_angles(x + h + xi.x0, xi.L, chain.L1)
    minus = _constructed_angles(x - h + xi.x0, xi.L, chain.L1)
    ratios = mechanism.velocity_ratios(x, xi.L, chain.L1, xi.x0)
    for k, a_plus, a_minus in zip(ratios, plus, minus, strict=True):
        np.testing.assert_allclose(k, (a_plus - a_minus) / (2 * h), rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(sum(ratios), 0.0, atol=1e-12)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_seed_k1_expression_has_the_wrong_sign(name: str) -> None:
    """The seed prints k1 = -(x + x0) / (L L1 sin q); central differences of q(x) give its negative everywhere."""
    chain, xi = CHAINS[name], CHAINS[name].default_lengths
    x, h = _sample_strokes(name), 1e-6
    q = _constructed_angles(x + xi.x0, xi.L, chain.L1)[0]
    seed_k1 = -(x + xi.x0) / (xi.L * chain.L1 * np.sin(q))
    dq_dx = (
        _constructed_angles(x + h + xi.x0, xi.L, chain.L1)[0] - _constructed_angles(x - h + xi.x0, xi.L, chain.L1)[0]
    ) / (2 * h)
    np.testing.assert_allclose(-seed_k1, dq_dx, rtol=1e-7)
    assert np.all(np.sign(seed_k1) == -np.sign(dq_dx)) and np.all(np.abs(dq_dx) > 0.1)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_velocity_ratio_rates_match_central_differences_in_time(name: str) -> None:
    """dk1, dk2, dk3 (eq. 04) equal d/dt of k along a moving stroke x(t)."""
    chain, xi = CHAINS[name], CHAINS[name].default_lengths
    x_min, x_max = mechanism.stroke_bounds(chain, xi)
    mid, amp = 0.5 * (x_min + x_max), 0.3 * (x_max - x_min)
    t, h = np.linspace(0.0, 3.0, 31), 1e-6
    x_of = lambda time: mid + amp * np.sin(1.3 * time)  # noqa: E731
    dx = amp * 1.3 * np.cos(1.3 * t)
    rates = mechanism.velocity_ratio_rates(x_of(t), dx, xi.L, chain.L1, xi.x0)
    plus = mechanism.velocity_ratios(x_of(t + h), xi.L, chain.L1, xi.x0)
    minus = mechanism.velocity_ratios(x_of(t - h), xi.L, chain.L1, xi.x0)
    for rate, k_plus, k_minus in zip(rates, plus, minus, strict=True):
        np.testing.assert_allclose(rate, (k_plus - k_minus) / (2 * h), rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_actuator_motion_matches_differentiated_joint_motion(name: str) -> None:
    """joint_to_actuator gives dx, ddx equal to time differences of x(theta(t)), and inverts."""
    chain, xi = CHAINS[name], CHAINS[name].default_lengths
    low, high = chain.joint_range
    mid, amp, w = 0.5 * (low + high), 0.3 * (high - low), 0.9
    t, h = np.linspace(0.0, 4.0, 21), 1e-4
    theta = lambda time: mid + amp * np.sin(w * time)  # noqa: E731
    x, dx, ddx = mechanism.joint_to_actuator(chain, xi, theta(t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t))
    x_plus = mechanism.joint_to_stroke(chain, xi, theta(t + h))
    x_minus = mechanism.joint_to_stroke(chain, xi, theta(t - h))
    np.testing.assert_allclose(dx, (x_plus - x_minus) / (2 * h), rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(ddx, (x_plus - 2 * x + x_minus) / h**2, rtol=1e-4, atol=1e-6)
    theta_back, dtheta_back, ddtheta_back = mechanism.actuator_to_joint(chain, xi, x, dx, ddx)
    np.testing.assert_allclose(theta_back, theta(t), atol=1e-12)
    np.testing.assert_allclose(dtheta_back, amp * w * np.cos(w * t), atol=1e-12)
    np.testing.assert_allclose(ddtheta_back, -amp * w * w * np.sin(w * t), atol=1e-10)


def test_xs031_joint_to_triangle_relations_use_the_source_betas() -> None:
    """q1 = theta1 - pi/2 - beta1 - beta2 and q2 = theta2 - beta3 - beta4 (source relations)."""
    beta1, beta2 = np.arctan2(374.261, 935), np.arctan2(45.757, 373.313)
    beta3, beta4 = np.arctan2(139.50, 1132.19), np.arctan2(88.061, 296.198)
    theta = np.array([0.3, 0.7])
    np.testing.assert_allclose(
        mechanism.boom_rotation(CRANE.lift, theta), theta - np.pi / 2 - beta1 - beta2, atol=1e-12
    )
    np.testing.assert_allclose(mechanism.boom_rotation(CRANE.tilt, theta), theta - beta3 - beta4, atol=1e-12)


def _source_stroke(L: float, L11: float, x0: float, boom_rotation: np.ndarray) -> np.ndarray:
    """Source eq. 1: x1 = sqrt(L1^2 + L11^2 + 2 L1 L11 cos q1) - x10."""
    return np.sqrt(L**2 + L11**2 + 2 * L * L11 * np.cos(boom_rotation)) - x0


@pytest.mark.parametrize(
    ("name", "expected_degrees"),
    [("lift", (-9.2397, 118.8031)), ("tilt", (-146.115, -0.44969))],
)
def test_xs031_reachable_ranges_from_the_0p59_m_stroke(name: str, expected_degrees: tuple[float, float]) -> None:
    """Reachable theta ranges agree with a brute-force scan of the source's closure equation.

    Lift: the 0.59 m stroke would pass the toggle (L + L1 < x0 + 0.59), so its upper end is
    the flat triangle at theta1 = joint_offset; tilt: both ends are the stroke's.
    """
    chain = CHAINS[name]
    xi = chain.default_lengths
    low, high = mechanism.reachable_joint_range(chain, xi)
    theta = np.linspace(chain.joint_offset - np.pi + 1e-9, chain.joint_offset - 1e-9, 2_000_001)
    x = _source_stroke(xi.L, chain.L1, xi.x0, theta - chain.joint_offset)
    ok = (x >= 0.0) & (x <= 0.59)
    step = theta[1] - theta[0]
    assert abs(theta[ok][0] - low) <= 2 * step
    assert abs(theta[ok][-1] - high) <= 2 * step
    np.testing.assert_allclose(np.degrees([low, high]), expected_degrees, atol=1e-3)


def test_stroke_bounds_follow_stroke_rod_length_and_triangle() -> None:
    """Usable stroke is [0, min(stroke, Lc, L + L1 - x0)]."""
    chain = CRANE.lift
    assert mechanism.stroke_bounds(chain, chain.default_lengths) == pytest.approx(
        (0.0, 1.0071227324212 + 0.37610632101293 - 0.83)
    )
    short_rod = ChainLengths(L=1.2, Lc0=0.1, Lc=0.5)
    assert mechanism.stroke_bounds(chain, short_rod)[1] == pytest.approx(0.5)

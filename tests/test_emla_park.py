"""Amplitude-invariant Park transform (eqs. Park_Transformation, abc_to_dq): inverse, amplitude, power."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from hiab_sim.emla import abc_to_dq0, dq0_power, dq0_to_abc, line_voltage_rms, park_matrix

finite = st.floats(-1e3, 1e3, allow_nan=False)
angles = st.floats(-20.0, 20.0, allow_nan=False)


@settings(max_examples=100, deadline=None)
@given(x=arrays(float, (3, 5), elements=finite), theta=arrays(float, (5,), elements=angles))
def test_abc_to_dq0_to_abc_round_trip_is_identity(x: np.ndarray, theta: np.ndarray) -> None:
    """Transforms abc -> dq0 -> abc and dq0 -> abc -> dq0 return the input (zero sequence too)."""
    np.testing.assert_allclose(dq0_to_abc(abc_to_dq0(x, theta), theta), x, atol=1e-9)
    np.testing.assert_allclose(abc_to_dq0(dq0_to_abc(x, theta), theta), x, atol=1e-9)


@settings(max_examples=100, deadline=None)
@given(
    v=arrays(float, (3, 4), elements=finite),
    i=arrays(float, (3, 4), elements=finite),
    theta=arrays(float, (4,), elements=angles),
)
def test_three_phase_power_equals_three_halves_dq_power(v: np.ndarray, i: np.ndarray, theta: np.ndarray) -> None:
    """sum_k v_k i_k = 3/2 (v_d i_d + v_q i_q) + 3 v_0 i_0 for the amplitude-invariant transform."""
    p_abc = np.sum(v * i, axis=0)
    p_dq = dq0_power(abc_to_dq0(v, theta), abc_to_dq0(i, theta))
    np.testing.assert_allclose(p_dq, p_abc, atol=1e-6 * (1 + np.abs(p_abc).max()))


def test_balanced_set_of_peak_amplitude_x_has_dq_magnitude_x() -> None:
    """A balanced phase set X cos(theta_e - s_k + phi) maps to constant (X cos phi, X sin phi, 0)."""
    theta = np.linspace(0.0, 4 * np.pi, 50)
    amplitude, phi = 7.0, 0.3
    shifts = np.array([0.0, 2 * np.pi / 3, -2 * np.pi / 3])[:, None]
    x_abc = amplitude * np.cos(theta - shifts + phi)
    dq0 = abc_to_dq0(x_abc, theta)
    np.testing.assert_allclose(dq0[0], amplitude * np.cos(phi), atol=1e-12)
    np.testing.assert_allclose(dq0[1], amplitude * np.sin(phi), atol=1e-12)
    np.testing.assert_allclose(dq0[2], 0.0, atol=1e-12)


def test_line_voltage_rms_is_sqrt_three_halves_times_dq_magnitude() -> None:
    """The rms of v_a - v_b over one period equals sqrt(3/2 (v_d^2 + v_q^2))."""
    v_d, v_q = -120.0, 250.0
    theta = np.linspace(0.0, 2 * np.pi, 4001)[:-1]
    v_abc = dq0_to_abc(np.stack([np.full_like(theta, v_d), np.full_like(theta, v_q), 0 * theta]), theta)
    rms = np.sqrt(np.mean((v_abc[0] - v_abc[1]) ** 2))
    np.testing.assert_allclose(line_voltage_rms(v_d, v_q), rms, rtol=1e-12)


def test_park_matrix_rows_are_orthogonal_with_norms_three_halves_and_three_quarters() -> None:
    """P P^T = diag(3/2, 3/2, 3/4), which is why the power carries the 3/2 factor."""
    p = park_matrix(np.array([0.0, 1.3, -2.0]))
    np.testing.assert_allclose(
        p @ np.swapaxes(p, -1, -2), np.broadcast_to(np.diag([1.5, 1.5, 0.75]), (3, 3, 3)), atol=1e-14
    )

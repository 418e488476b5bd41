"""Screw buckling: Euler with end fixity, Johnson below the transition, exact partials w.r.t. Xi and q."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.emla.config import EmlaSet, ScrewColumn, load_emla_set
from hiab_sim.errors import InvalidInputError
from hiab_sim.structure.actuators import actuators, column_length
from hiab_sim.structure.buckling import (
    buckling_samples,
    critical_load,
    transition_slenderness,
    utilisation_partials,
)

PAYLOAD = np.array([0.0, -9.8066 * 250.0, 0.0])


@pytest.fixture(scope="module")
def emlas() -> EmlaSet:
    """The XS 031 EMLA set, with screw data."""
    return load_emla_set()


def _poses(crane: Crane, n: int = 7) -> np.ndarray:
    rng = np.random.default_rng(3)
    lo = np.array([crane.lift.joint_range[0], crane.tilt.joint_range[0], 0.0])
    hi = np.array([crane.lift.joint_range[1], crane.tilt.joint_range[1], crane.telescope.stroke])
    return lo + (hi - lo) * rng.uniform(0.05, 0.95, size=(n, 3))


def test_euler_and_johnson_meet_with_equal_value_and_slope() -> None:
    """At lambda_c both formulas give A sigma_y / 2 and the critical load has no kink (Johnson is tangent)."""
    screw = ScrewColumn(0.04, 2.06e11, 6.5e8, 1.0)
    radius = screw.root_diameter / 4.0
    l_c = transition_slenderness(screw) * radius
    (below, above), (slope_below, slope_above) = critical_load(screw, np.array([l_c * (1 - 1e-9), l_c * (1 + 1e-9)]))
    area = math.pi * screw.root_diameter**2 / 4.0
    assert below == pytest.approx(area * screw.yield_strength / 2.0, rel=1e-7)
    assert above == pytest.approx(below, rel=1e-7)
    assert slope_above == pytest.approx(slope_below, rel=1e-6)


def test_long_screw_matches_the_thk_catalogue_formula() -> None:
    """Fixed-supported (eta1 = 2), long screw: P_cr / 2 equals THK's eq. (5) shortcut 10 d1^4 / la^2 x 1e4 N (mm)."""
    screw = ScrewColumn(0.032, 2.06e11, 6.5e8, 2.0)
    la = 3.0
    load, _ = critical_load(screw, la)
    thk = 10.0 * (screw.root_diameter * 1e3) ** 4 / (la * 1e3) ** 2 * 1e4
    assert float(load) / 2.0 == pytest.approx(thk, rel=5e-3)


@settings(max_examples=40, deadline=None)
@given(st.floats(0.05, 5.0), st.floats(0.05, 5.0), st.sampled_from([0.25, 1.0, 2.0, 4.0]))
def test_critical_load_falls_with_length_and_never_exceeds_the_squash_load(a: float, b: float, fixity: float) -> None:
    """P_cr is non-increasing in the column length and below A sigma_y for any length and fixity."""
    screw = ScrewColumn(0.0435, 2.06e11, 6.5e8, fixity)
    short, long_ = sorted((a, b))
    (p_short, p_long), _ = critical_load(screw, np.array([short, long_]))
    area = math.pi * screw.root_diameter**2 / 4.0
    assert p_long <= p_short * (1 + 1e-12)
    assert 0.0 < p_short <= area * screw.yield_strength


def test_critical_load_slope_matches_finite_differences() -> None:
    """dP_cr/dl of both branches agrees with central differences."""
    screw = ScrewColumn(0.0435, 2.06e11, 6.5e8, 1.0)
    size = np.array([0.3, 0.6, 0.85, 1.2, 2.0])
    h = 1e-6
    _, slope = critical_load(screw, size)
    fd = (critical_load(screw, size + h)[0] - critical_load(screw, size - h)[0]) / (2 * h)
    np.testing.assert_allclose(slope, fd, rtol=1e-6)


def test_column_length_is_the_pin_to_pin_distance_with_exact_partials(crane: Crane) -> None:
    """The column length is x + x0 of a chain; ds/dtheta and ds/dXi match central differences of s."""
    q = _poses(crane)
    base = crane.default_lengths
    for actuator in actuators(crane):
        if actuator.chain is None:
            continue
        _, ds_dq, ds_dxi = column_length(crane, base, actuator, q)
        h = 1e-7
        for j in range(6):
            up, down = base.as_array(), base.as_array()
            up[j] += h
            down[j] -= h
            fd = (
                column_length(crane, LinkLengths.from_array(up), actuator, q)[0]
                - column_length(crane, LinkLengths.from_array(down), actuator, q)[0]
            ) / (2 * h)
            np.testing.assert_allclose(ds_dxi[:, j], fd, atol=1e-7)
        dq = np.zeros_like(q)
        dq[:, actuator.column] = h
        fd_q = (column_length(crane, base, actuator, q + dq)[0] - column_length(crane, base, actuator, q - dq)[0]) / (
            2 * h
        )
        np.testing.assert_allclose(ds_dq, fd_q, rtol=1e-6)


def _forces(crane: Crane, xi: np.ndarray, q: np.ndarray) -> np.ndarray:
    zero = np.zeros_like(q)
    return batched_inverse_dynamics(crane, xi[None], q, zero, zero, PAYLOAD)[0][0]


def test_utilisation_gradient_matches_finite_differences_of_the_whole_chain(crane: Crane, emlas: EmlaSet) -> None:
    """du/dXi and du/dq (forces from the analytic ID, their partials by differences) match differences of u."""
    q = _poses(crane)
    xi0 = crane.default_lengths.as_array()
    h = 1e-6

    def u(xi: np.ndarray, pos: np.ndarray) -> np.ndarray:
        return buckling_samples(crane, emlas, LinkLengths.from_array(xi), pos, _forces(crane, xi, pos)).utilisation

    df_dxi = np.zeros((q.shape[0], 3, 6))
    du_dxi_fd = np.zeros((q.shape[0], 3, 6))
    for j in range(6):
        e = np.zeros(6)
        e[j] = h
        df_dxi[:, :, j] = (_forces(crane, xi0 + e, q) - _forces(crane, xi0 - e, q)) / (2 * h)
        du_dxi_fd[:, :, j] = (u(xi0 + e, q) - u(xi0 - e, q)) / (2 * h)
    df_dq = np.zeros((q.shape[0], 3, 3))
    du_dq_fd = np.zeros((q.shape[0], 3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        df_dq[:, :, j] = (_forces(crane, xi0, q + e) - _forces(crane, xi0, q - e)) / (2 * h)
        du_dq_fd[:, :, j] = (u(xi0, q + e) - u(xi0, q - e)) / (2 * h)
    du_dq, du_dxi = utilisation_partials(crane, emlas, crane.default_lengths, q, _forces(crane, xi0, q), df_dq, df_dxi)
    np.testing.assert_allclose(du_dxi, du_dxi_fd, atol=1e-5)
    np.testing.assert_allclose(du_dq, du_dq_fd, atol=1e-5)
    assert np.max(np.abs(du_dxi)) > 0.1  # the rows do depend on Xi


def test_actuator_without_screw_data_gives_no_row(crane: Crane, emlas: EmlaSet) -> None:
    """An EMLA without a screw section is not checked; the others still are."""
    partial = EmlaSet(emlas.lift, emlas.tilt, replace(emlas.telescope, screw=None), emlas.battery)
    q = _poses(crane, 3)
    out = buckling_samples(crane, partial, crane.default_lengths, q, np.ones((3, 3)) * 1e4)
    assert out.names == (emlas.lift.name, emlas.tilt.name)
    assert out.utilisation.shape == (3, 2)


def test_out_of_range_safety_factor_is_rejected(crane: Crane, emlas: EmlaSet) -> None:
    """A safety factor below 1 names the field."""
    with pytest.raises(InvalidInputError, match="buckling_safety_factor"):
        buckling_samples(crane, emlas, crane.default_lengths, _poses(crane, 2), np.zeros((2, 3)), safety_factor=0.5)


def test_screw_data_out_of_range_is_rejected() -> None:
    """A yield strength above the modulus or a zero diameter is refused at construction."""
    with pytest.raises(InvalidInputError, match="yield_strength"):
        ScrewColumn(0.04, 2.0e11, 3.0e11, 1.0)
    with pytest.raises(InvalidInputError, match="root_diameter"):
        ScrewColumn(0.0, 2.0e11, 6e8, 1.0)

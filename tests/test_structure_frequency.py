"""Natural frequencies: two mass-matrix paths agree; a free vibration of the spring-mounted model confirms them."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane.description import Crane
from hiab_sim.emla.config import EmlaSet, load_emla_set
from hiab_sim.errors import InvalidInputError
from hiab_sim.structure.free_vibration import FreeVibration, free_vibration_frequency, spectrum_peak_Hz
from hiab_sim.structure.natural_frequency import (
    axial_stiffness,
    bandwidth_margin,
    mass_matrix,
    natural_frequencies,
    working_range_poses,
)
from hiab_sim.structure.natural_frequency_mujoco import mujoco_mass_matrix


@pytest.fixture(scope="module")
def emlas() -> EmlaSet:
    """The XS 031 EMLA set with drive-train stiffness data."""
    return load_emla_set()


def test_analytic_and_mujoco_mass_matrices_agree(crane: Crane) -> None:
    """Sum of J^T G J over the links equals mj_fullM projected through the loop Jacobian, and so do the J_x."""
    poses = working_range_poses(crane, (3, 3, 2))
    M, jx = mass_matrix(crane, crane.default_lengths, poses)
    M2, jx2 = mujoco_mass_matrix(crane, None, poses)
    assert np.max(np.abs(M - M2)) < 1e-10 * np.max(np.abs(M))
    assert np.max(np.abs(jx - jx2)) < 1e-10


def test_drive_stiffness_is_the_series_sum_of_its_parts(emlas: EmlaSet) -> None:
    """At zero stroke, 1/k = l0/(E A) + 1/k_nut + 1/k_bearing + 2/k_pin, written out with the file's numbers."""
    p = emlas.lift
    assert p.screw is not None and p.stiffness is not None
    area = math.pi * 0.0435**2 / 4.0
    hand = 1.0 / (0.10 / (2.06e11 * area) + 1.0 / 1.0e9 + 1.0 / 1.0e9 + 2.0 / 2.0e9)
    assert float(axial_stiffness(p, 0.0)) == pytest.approx(hand, rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_drive_stiffness_falls_with_stroke_and_stays_below_each_part(a: float, b: float) -> None:
    """A longer loaded screw is softer; the series stiffness is below the stiffest-free part (the nut)."""
    p = load_emla_set().tilt
    assert p.stiffness is not None
    low, high = sorted((a, b))
    k_low, k_high = axial_stiffness(p, np.array([low, high]))
    assert k_high <= k_low
    assert k_low < p.stiffness.nut_stiffness


@pytest.mark.sim
@pytest.mark.parametrize("pose", [(0.5, -1.0, 0.5), (1.2, -0.5, 1.0)])
def test_lowest_frequency_matches_a_free_vibration_in_mujoco(crane: Crane, emlas: EmlaSet, pose: tuple) -> None:
    """The FFT peak of the spring-mounted MuJoCo model's free vibration is within 1 % of the eigenvalue's frequency."""
    modes = natural_frequencies(crane, emlas, crane.default_lengths, np.array([pose]))
    simulated = free_vibration_frequency(crane, emlas, crane.default_lengths, pose, FreeVibration(mode=0))
    assert simulated == pytest.approx(float(modes.lowest_Hz[0]), rel=0.01)


@pytest.mark.sim
def test_payload_held_at_the_tcp_matches_a_free_vibration_with_a_point_mass(crane: Crane, emlas: EmlaSet) -> None:
    """300 kg at the TCP (a body in MuJoCo; mass and weight in the eigenproblem): frequencies agree within 1 %."""
    pose = (0.5, -1.0, 0.5)
    weight = np.array([0.0, -300.0 * crane.gravity, 0.0])
    loaded = natural_frequencies(crane, emlas, crane.default_lengths, np.array([pose]), weight, payload_kg=300.0)
    empty = natural_frequencies(crane, emlas, crane.default_lengths, np.array([pose]))
    simulated = free_vibration_frequency(
        crane, emlas, crane.default_lengths, pose, FreeVibration(mode=0), payload_kg=300.0
    )
    assert simulated == pytest.approx(float(loaded.lowest_Hz[0]), rel=0.01)
    assert loaded.lowest_Hz[0] < 0.9 * empty.lowest_Hz[0]  # the payload matters


@pytest.mark.sim
def test_second_frequency_matches_a_free_vibration_in_mujoco(crane: Crane, emlas: EmlaSet) -> None:
    """The second mode too: the FFT of its free vibration within 1 % of its eigenvalue."""
    pose = (0.0, -2.0, 0.0)
    modes = natural_frequencies(crane, emlas, crane.default_lengths, np.array([pose]))
    simulated = free_vibration_frequency(crane, emlas, crane.default_lengths, pose, FreeVibration(mode=1))
    assert simulated == pytest.approx(float(modes.frequency_Hz[0, 1]), rel=0.01)


def test_spectrum_peak_finds_a_sinusoid_between_bins() -> None:
    """A 7.3 Hz sine over 3.1 s (not a whole number of bins) is found to 1e-4 relative."""
    t = np.arange(0.0, 3.1, 1e-3)
    assert spectrum_peak_Hz(np.sin(2 * math.pi * 7.3 * t + 0.4), 1e-3) == pytest.approx(7.3, rel=1e-4)


def test_mode_shapes_are_mass_orthonormal(crane: Crane, emlas: EmlaSet) -> None:
    """phi^T M phi = I with the MuJoCo mass matrix: the analytic shapes diagonalise the other path's M."""
    poses = working_range_poses(crane, (2, 2, 2))
    modes = natural_frequencies(crane, emlas, crane.default_lengths, poses)
    M, _ = mujoco_mass_matrix(crane, None, poses)
    gram = np.einsum("tia,tij,tjb->tab", modes.shape, M, modes.shape)
    np.testing.assert_allclose(gram, np.broadcast_to(np.eye(3), gram.shape), atol=1e-9)


def test_bandwidth_check_uses_the_lowest_frequency_over_the_poses() -> None:
    """A third of the lowest of several frequencies is the limit: at it the margin is 0, above it negative."""
    lowest = np.array([12.0, 6.0, 9.0])
    assert bandwidth_margin(2.0, lowest) == pytest.approx(0.0)
    assert bandwidth_margin(3.0, lowest) < 0.0 < bandwidth_margin(1.0, lowest)
    assert bandwidth_margin(1.0, lowest) == pytest.approx(0.5)
    assert bandwidth_margin(3.0, lowest, max_ratio=0.5) == pytest.approx(0.0)
    with pytest.raises(InvalidInputError, match="bandwidth_Hz"):
        bandwidth_margin(-1.0, lowest)

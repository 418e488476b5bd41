"""Mounting space: pivot positions vs forward kinematics, polygon rows vs point-in-polygon, exact Jacobians."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as MplPath

from hiab_sim.crane import kinematics
from hiab_sim.crane.description import ChainLengths, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.crane.mounting import (
    MountingSpace,
    base_pivot,
    boom_centre_line,
    built_space,
    clearance_margins,
    mounting_margins,
    polygon_margins,
    rod_end_pivot,
)
from hiab_sim.errors import ConfigError, InvalidInputError

CRANE = load_crane("xs031")
SPACE = built_space(CRANE)


def _lengths(lift_l: float, tilt_l: float) -> LinkLengths:
    return LinkLengths(ChainLengths(lift_l, 0.2, 0.7), ChainLengths(tilt_l, 0.15, 0.65))


@settings(max_examples=40, deadline=None)
@given(st.floats(0.85, 1.3), st.floats(0.95, 1.35))
def test_mounting_jacobian_matches_central_differences(lift_l: float, tilt_l: float) -> None:
    """dg/dXi of every mounting row equals central differences to 1e-7 (all six columns)."""
    lengths = _lengths(lift_l, tilt_l)
    margins = mounting_margins(SPACE, CRANE, lengths)
    x = lengths.as_array()
    h = 1e-6
    fd = np.zeros_like(margins.jacobian)
    for j in range(6):
        step = np.zeros(6)
        step[j] = h
        up = mounting_margins(SPACE, CRANE, LinkLengths.from_array(x + step)).values
        down = mounting_margins(SPACE, CRANE, LinkLengths.from_array(x - step)).values
        fd[:, j] = (up - down) / (2 * h)
    np.testing.assert_allclose(margins.jacobian, fd, atol=1e-7)


@settings(max_examples=60, deadline=None)
@given(st.floats(0.7, 1.4), st.floats(0.8, 1.5))
def test_polygon_rows_agree_with_point_in_polygon(lift_l: float, tilt_l: float) -> None:
    """All edge rows >= 0 exactly when matplotlib's point-in-polygon test puts the pivot inside."""
    lengths = _lengths(lift_l, tilt_l)
    margins = polygon_margins(SPACE, CRANE, lengths)
    for chain in CRANE.chains:
        rows = np.array([v for n, v in zip(margins.names, margins.values, strict=True) if f".{chain.name} " in n])
        if np.min(np.abs(rows)) < 1e-9:
            continue  # on an edge: the two tests may round differently
        p, _ = base_pivot(chain, lengths)
        inside = MplPath(np.asarray(SPACE.polygon(chain.name))).contains_point(p)
        assert inside == bool(np.all(rows > 0.0))


def test_built_space_admits_the_built_pivot_travel_of_0_1_m_either_way() -> None:
    """The built crane is inside its space with 0.05 m across and 0.10 m along; L +- 0.1 m reaches an edge."""
    default = CRANE.default_lengths
    margins = polygon_margins(SPACE, CRANE, default)
    np.testing.assert_allclose(np.sort(margins.values), [0.05] * 4 + [0.10] * 4, atol=1e-12)
    for dl, sign in ((0.1, 1), (-0.1, 1), (0.101, -1), (-0.101, -1)):
        lengths = _lengths(default.lift.L + dl, default.tilt.L + dl)
        worst = np.min(polygon_margins(SPACE, CRANE, lengths).values)
        assert sign * worst >= -1e-12


def test_pivots_agree_with_forward_kinematics() -> None:
    """Base pivot = cylinder frame origin, rod-end pivot = (L1, 0) on the boom, as forward kinematics has them."""
    lengths = _lengths(1.1, 1.2)
    theta1 = np.linspace(*CRANE.lift.joint_range, 7)
    theta2 = np.linspace(*CRANE.tilt.joint_range, 7)
    frames = kinematics.forward_kinematics(CRANE, lengths, theta1, theta2, np.full(7, 0.3))
    np.testing.assert_allclose(
        frames.position["lift_cylinder"][:, :2], np.tile(base_pivot(CRANE.lift, lengths)[0], (7, 1))
    )
    np.testing.assert_allclose(
        frames.point("lift_boom", [CRANE.lift.L1, 0, 0])[:, :2], rod_end_pivot(CRANE.lift, theta1)
    )
    # the tilt chain lives in the lift boom frame: map world points back into it
    rot, pos = frames.rotation["lift_boom"], frames.position["lift_boom"]

    def in_lift_boom(world: np.ndarray) -> np.ndarray:
        return np.einsum("tji,tj->ti", rot, world - pos)[:, :2]

    np.testing.assert_allclose(
        in_lift_boom(frames.position["tilt_cylinder"]), np.tile(base_pivot(CRANE.tilt, lengths)[0], (7, 1)), atol=1e-12
    )
    on_boom = frames.point("tilt_boom", [CRANE.tilt.L1, 0, 0])
    np.testing.assert_allclose(in_lift_boom(on_boom), rod_end_pivot(CRANE.tilt, theta2), atol=1e-12)


def test_boom_clearance_matches_a_brute_force_sweep() -> None:
    """The boom clearance row equals the distance to densely sampled boom points from forward kinematics (1 mm)."""
    lengths = _lengths(1.2, 1.3)
    space = MountingSpace(clearance=0.05, samples=401)
    margins = clearance_margins(space, CRANE, lengths)
    t = np.linspace(0.0, 1.0, 401)
    for chain in CRANE.chains:
        theta = np.interp(t, [0, 1], chain.joint_range)
        other = np.full_like(theta, np.mean(CRANE.tilt.joint_range if chain.name == "lift" else CRANE.lift.joint_range))
        t1, t2 = (theta, other) if chain.name == "lift" else (other, theta)
        frames = kinematics.forward_kinematics(CRANE, lengths, t1, t2, np.zeros_like(t))
        line = boom_centre_line(CRANE, chain)
        dense = np.concatenate([a + np.linspace(0, 1, 400)[:, None] * (b - a) for a, b in itertools.pairwise(line)])
        points = np.stack([frames.point(f"{chain.name}_boom", [x, y, 0.0]) for x, y in dense], axis=1)  # (T, P, 3)
        pivot = frames.position[f"{chain.name}_cylinder"][:, None, :]
        brute = np.min(np.linalg.norm(points - pivot, axis=-1))
        row = [
            v
            for n, v in zip(margins.names, margins.values, strict=True)
            if n.startswith(f"mounting.{chain.name}") and "boom over" in n
        ]
        assert row[0] + space.clearance == pytest.approx(brute, abs=1e-3)


def test_tilt_pivot_clearance_from_the_lift_rod_end_pin() -> None:
    """The tilt base pivot row is |p - Tc1| - clearance: zero exactly where the pivot is one clearance from the pin."""
    lengths = _lengths(1.0, 1.2)
    margins = clearance_margins(SPACE, CRANE, lengths)
    p, _ = base_pivot(CRANE.tilt, lengths)
    row = margins.values[margins.names.index("mounting.tilt base pivot clear of the lift rod-end pivot")]
    assert row == pytest.approx(np.hypot(p[0] - CRANE.lift.L1, p[1]) - SPACE.clearance, abs=1e-15)


@pytest.mark.parametrize(
    ("polygon", "message"),
    [
        (((0, 0), (1, 0)), "at least 3 vertices"),
        (((0, 0), (0, 1), (1, 0)), "counter-clockwise"),
        (((0, 0), (2, 0), (1, 0.5), (2, 2), (0, 2)), "strictly convex"),
        (((0, 0), (1, 0), (1, 0), (0, 1)), "consecutive vertices"),
        (((0, 0), (1, 0), (float("nan"), 1)), "finite"),
    ],
)
def test_bad_polygons_are_rejected_with_the_field(polygon: tuple, message: str) -> None:
    """A polygon that is too small, clockwise, non-convex, degenerate or not finite is rejected naming the field."""
    with pytest.raises(InvalidInputError, match=f"mounting.tilt.*{message}"):
        MountingSpace(tilt=polygon)


def test_from_mapping_round_trips_and_rejects_unknown_keys() -> None:
    """from_mapping rebuilds the built space from plain lists; unknown keys and a bad clearance are one-line errors."""
    data = {"lift": [list(v) for v in SPACE.lift or ()], "tilt": [list(v) for v in SPACE.tilt or ()], "clearance": 0.05}
    assert MountingSpace.from_mapping(data) == SPACE
    assert MountingSpace.from_mapping({}) == MountingSpace()
    with pytest.raises(ConfigError, match="unknown key"):
        MountingSpace.from_mapping({"lifts": []})
    with pytest.raises(InvalidInputError, match=r"mounting\.clearance"):
        MountingSpace.from_mapping({"clearance": -0.01})
    with pytest.raises(ConfigError, match=r"mounting.lift\[1\]"):
        MountingSpace.from_mapping({"lift": [[0, 0], [1]]})

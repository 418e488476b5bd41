"""The soil-cutting force (fundamental earthmoving equation) against Rankine and a direct wedge equilibrium."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.soil import (
    SoilProperties,
    blade_force,
    failure_plane_angle,
    force_on_plane,
    tool_force_world,
)

G = 9.81


def test_upright_smooth_blade_in_sand_meets_the_rankine_passive_force() -> None:
    """Upright, frictionless blade, cohesionless soil: P = gamma g d^2 K_p / 2 with K_p = tan^2(45 deg + phi/2).

    Rankine's passive earth pressure on a smooth vertical wall (the Coulomb wedge at beta* = 45 deg - phi/2).
    """
    phi = np.radians(33.0)
    soil = SoilProperties(1700.0, phi, 0.0, 0.0, 0.0, 0.0, "test values")
    depth = np.array([0.1, 0.25, 0.4])
    along, up = blade_force(soil, G, np.pi / 2, depth, width_m=0.6)
    rankine = 0.5 * 1700.0 * G * depth**2 * np.tan(np.pi / 4 + phi / 2) ** 2 * 0.6
    np.testing.assert_allclose(-along, rankine, rtol=1e-10)
    np.testing.assert_allclose(up, 0.0, atol=1e-9 * rankine.max())
    np.testing.assert_allclose(failure_plane_angle(soil, G, np.pi / 2, depth), np.pi / 4 - phi / 2, atol=1e-7)


def _wedge_equilibrium(soil: SoilProperties, alpha: float, depth: float, beta: float) -> np.ndarray:
    """Blade force on the soil per metre width [N/m] from the wedge's two force balances (2x2 solve).

    Unknown magnitudes: P along (sin(alpha + delta), cos(alpha + delta)) and the failure-plane force
    along (-sin(beta + phi), cos(beta + phi)); known: weight, surcharge, cohesion along the plane,
    adhesion along the blade.
    """
    phi, delta = soil.friction_angle_rad, soil.tool_friction_angle_rad
    top = depth * (1 / np.tan(alpha) + 1 / np.tan(beta))
    known = np.array([0.0, -soil.density_kg_m3 * G * 0.5 * depth * top - soil.surcharge_Pa * top])
    known += soil.cohesion_Pa * depth / np.sin(beta) * np.array([-np.cos(beta), -np.sin(beta)])
    adhesion = soil.adhesion_Pa * depth / np.sin(alpha) * np.array([np.cos(alpha), -np.sin(alpha)])
    e_p = np.array([np.sin(alpha + delta), np.cos(alpha + delta)])
    e_r = np.array([-np.sin(beta + phi), np.cos(beta + phi)])
    p, _ = np.linalg.solve(np.column_stack([e_p, e_r]), -(known + adhesion))
    return np.asarray(p * e_p + adhesion)


@settings(max_examples=40, deadline=None)
@given(
    st.floats(np.radians(20), np.radians(120)),
    st.floats(0.02, 0.5),
    st.floats(np.radians(15), np.radians(42)),
    st.floats(0.0, 30e3),
    st.floats(0.0, 0.7),
    st.floats(0.0, 10e3),
    st.floats(0.0, 5e3),
)
def test_blade_force_equals_the_wedge_equilibrium(
    alpha: float, depth: float, phi: float, cohesion: float, delta_ratio: float, adhesion: float, surcharge: float
) -> None:
    """For any soil and rake angle, the closed-form N factors give the wedge's own force balance at beta*."""
    assume(alpha + (1.0 + delta_ratio) * phi < np.pi - 0.2)  # a failure wedge exists (alpha + delta + phi < pi)
    soil = SoilProperties(1800.0, phi, cohesion, delta_ratio * phi, adhesion, surcharge, "test values")
    beta = float(failure_plane_angle(soil, G, alpha, depth)[0])
    along, up = blade_force(soil, G, alpha, depth, width_m=1.0)
    expected = _wedge_equilibrium(soil, alpha, depth, beta)
    np.testing.assert_allclose([-along[0], -up[0]], expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())
    # beta* is the least-force plane
    around = force_on_plane(soil, G, np.array(alpha), np.array(depth), np.array([beta - 1e-3, beta + 1e-3]))
    assert np.all(around >= force_on_plane(soil, G, np.array(alpha), np.array(depth), np.array(beta)))


def test_world_force_opposes_the_travel_and_vanishes_above_ground() -> None:
    """The tool travelling along -x is pushed towards +x; depth 0 gives no force; bad inputs name their field."""
    soil = SoilProperties(1600.0, np.radians(30.0), 5e3, np.radians(20.0), 0.0, 0.0, "test values")
    force = tool_force_world(soil, G, [1.2, 1.2], [0.2, 0.0], 0.5, [-1.0, -1.0])
    assert force[0, 0] > 0.0
    np.testing.assert_array_equal(force[1], [0.0, 0.0])
    with pytest.raises(InvalidInputError, match="depth_m"):
        blade_force(soil, G, 1.0, -0.1, 0.5)
    with pytest.raises(InvalidInputError, match="rake_angle_rad"):
        blade_force(soil, G, 0.0, 0.1, 0.5)
    with pytest.raises(InvalidInputError, match="travel_sign"):
        tool_force_world(soil, G, 1.0, 0.1, 0.5, 0.5)
    with pytest.raises(InvalidInputError, match=r"soil\.friction_angle_rad"):
        SoilProperties(1600.0, 2.0, 0.0, 0.0, 0.0, 0.0, "test values")
    with pytest.raises(InvalidInputError, match=r"soil\.source"):
        SoilProperties(1600.0, 0.5, 0.0, 0.0, 0.0, 0.0, " ")


def test_a_blade_too_steep_for_a_failure_wedge_is_refused() -> None:
    """A rake angle with alpha + delta + phi >= pi leaves no failure wedge: refused, naming rake_angle_rad."""
    soil = SoilProperties(1700.0, np.radians(39.0), 0.0, np.radians(24.0), 0.0, 0.0, "test values")
    with pytest.raises(InvalidInputError, match="rake_angle_rad"):
        blade_force(soil, G, np.radians(118.0), 0.3, 0.5)

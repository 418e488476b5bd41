"""Soil-cutting resistance at a tool tip: the fundamental earthmoving equation (Reece 1964, McKyes 1985).

A flat blade of width w cuts a layer of depth d from a horizontal soil surface, moving along its
travel direction. The soil ahead fails along a plane from the blade tip at angle beta to the
surface; the wedge between blade and plane is in equilibrium under its weight, a surcharge q on its
top, the blade's force (at the soil-tool friction angle delta from the blade normal, plus adhesion
c_a along the blade) and the force of the soil below the plane (at the internal friction angle phi
from its normal, plus cohesion c along it). The blade's force on the soil is

    P = w (gamma g d^2 N_g + c d N_c + q d N_q + c_a d N_a)                 (Reece 1964)

with, for a blade at rake angle alpha from the surface (McKyes 1985, ch. 4; Blouin et al. 2001),

    D   = cos(alpha + delta) + sin(alpha + delta) cot(beta + phi)
    N_g = (cot alpha + cot beta) / (2 D),      N_q = 2 N_g
    N_c = (1 + cot beta cot(beta + phi)) / D,  N_a = (1 - cot alpha cot(beta + phi)) / D,

and the failure plane is the one that needs the least force, beta* = argmin P on
0 < beta < pi - alpha - delta - phi. P acts on the soil at angle delta from the blade normal
(e_P = (sin(alpha + delta), cos(alpha + delta)) in the cutting frame, x along the travel, y up);
the adhesion c_a w d / sin(alpha) acts down along the blade. The soil's force on the tool is the
reaction. (Dotting the wedge's force balance with the direction normal to the failure-plane force
eliminates that force and gives exactly these N factors.)

Sources: A. R. Reece, "The fundamental equation of earth-moving mechanics", Proc. Inst. Mech. Eng.
179 (1964); E. McKyes, *Soil Cutting and Tillage*, Elsevier (1985); S. Blouin, A. Hemami and
M. Lipsett, "Review of resistive force models for earthmoving processes", J. Aerospace Eng. 14(3)
(2001) 102-111. The model is quasi-static (no soil inertia) and assumes a planar failure surface and
a horizontal soil surface; it is the cutting resistance for a tool moving along its travel
direction, not a penetration or tool-filling model. Soil properties are the caller's data (no
default is given here: they vary by an order of magnitude between soils; state their source).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_non_negative, check_positive, check_range
from hiab_sim.errors import InvalidInputError

#: Golden-section refinement steps of the failure-plane angle (each shrinks the bracket by 0.618).
_GOLDEN_STEPS = 60
_GRID = 256  #: grid points of the failure-plane bracket


@dataclass(frozen=True)
class SoilProperties:
    """Mohr-Coulomb soil and soil-tool data of the fundamental earthmoving equation.

    Attributes:
        density_kg_m3: Bulk density gamma [kg/m^3] > 0.
        friction_angle_rad: Internal friction angle phi [rad] in [0, pi/2).
        cohesion_Pa: Cohesion c [Pa] >= 0.
        tool_friction_angle_rad: Soil-tool friction angle delta [rad] in [0, pi/2).
        adhesion_Pa: Soil-tool adhesion c_a [Pa] >= 0.
        surcharge_Pa: Pressure q on the soil surface above the wedge [Pa] >= 0.
        source: Where these numbers come from (required: soil data vary by an order of magnitude).

    """

    density_kg_m3: float
    friction_angle_rad: float
    cohesion_Pa: float
    tool_friction_angle_rad: float
    adhesion_Pa: float
    surcharge_Pa: float
    source: str

    def __post_init__(self) -> None:
        if not self.source.strip():
            raise InvalidInputError("soil.source", self.source, "must name where the soil data come from")
        check_positive("soil.density_kg_m3", self.density_kg_m3, "kg/m^3")
        check_range("soil.friction_angle_rad", self.friction_angle_rad, 0.0, np.pi / 2, "rad", high_open=True)
        check_non_negative("soil.cohesion_Pa", self.cohesion_Pa, "Pa")
        check_range("soil.tool_friction_angle_rad", self.tool_friction_angle_rad, 0.0, np.pi / 2, "rad", high_open=True)
        check_non_negative("soil.adhesion_Pa", self.adhesion_Pa, "Pa")
        check_non_negative("soil.surcharge_Pa", self.surcharge_Pa, "Pa")


def force_on_plane(soil: SoilProperties, gravity: float, alpha: Array, depth: Array, beta: Array) -> Array:
    """McKyes' P / w [N/m] (the blade's push along e_P) for failure-plane angles beta (broadcast with alpha, depth)."""
    phi, delta = soil.friction_angle_rad, soil.tool_friction_angle_rad
    cot_bp = 1.0 / np.tan(beta + phi)
    cot_a, cot_b = 1.0 / np.tan(alpha), 1.0 / np.tan(beta)
    D = np.cos(alpha + delta) + np.sin(alpha + delta) * cot_bp
    n_gamma = (cot_a + cot_b) / (2.0 * D)
    n_c = (1.0 + cot_b * cot_bp) / D
    n_a = (1.0 - cot_a * cot_bp) / D
    return (
        soil.density_kg_m3 * gravity * depth**2 * n_gamma
        + soil.cohesion_Pa * depth * n_c
        + soil.surcharge_Pa * depth * 2.0 * n_gamma
        + soil.adhesion_Pa * depth * n_a
    )


def failure_plane_angle(soil: SoilProperties, gravity: float, rake_angle_rad: ArrayLike, depth_m: ArrayLike) -> Array:
    """The failure-plane angle beta* [rad] that minimises P, per sample.

    P is finite for 0 < beta < pi - alpha - delta - phi (the wedge's force polygon closes) and grows
    without bound at both ends; beta* is bracketed on a grid over that interval and refined by
    golden section.
    """
    alpha = np.atleast_1d(np.asarray(rake_angle_rad, dtype=float))
    depth = np.atleast_1d(np.asarray(depth_m, dtype=float))
    alpha, depth = np.broadcast_arrays(alpha, depth)
    top = np.pi - alpha - soil.tool_friction_angle_rad - soil.friction_angle_rad
    if np.any(top <= 0.0):
        raise InvalidInputError(
            "rake_angle_rad",
            float(alpha[np.argmin(top)]),
            "alpha + delta + phi must be < pi for a failure wedge",
            "rad",
        )
    fraction = np.linspace(0.0, 1.0, _GRID + 2)[1:-1]
    grid = top[..., None] * fraction
    values = force_on_plane(soil, gravity, alpha[..., None], depth[..., None], grid)
    k = np.clip(np.argmin(values, axis=-1), 1, _GRID - 2)
    low, high = top * fraction[k - 1], top * fraction[k + 1]
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    for _ in range(_GOLDEN_STEPS):
        a = high - ratio * (high - low)
        b = low + ratio * (high - low)
        left = force_on_plane(soil, gravity, alpha, depth, a) < force_on_plane(soil, gravity, alpha, depth, b)
        high = np.where(left, b, high)
        low = np.where(left, low, a)
    return np.asarray(0.5 * (low + high))


def blade_force(
    soil: SoilProperties, gravity: float, rake_angle_rad: ArrayLike, depth_m: ArrayLike, width_m: float
) -> tuple[Array, Array]:
    """Force of the soil on the blade in the cutting frame [N]: (along travel, up), each per sample.

    The cutting frame has x along the travel direction and y up from the soil surface; the blade
    leans back from its tip at ``rake_angle_rad`` alpha in (0, pi) from the surface (pi/2: upright).
    The blade pushes the soil with McKyes' P along e_P = (sin(alpha + delta), cos(alpha + delta))
    and the adhesion c_a w d / sin(alpha) down along the blade, (cos alpha, -sin alpha); the soil
    pushes the blade back with the opposite. ``depth_m`` 0 gives no force.

    Raises:
        InvalidInputError: a rake angle outside (0, pi) or with no failure wedge, a negative or
            non-finite depth, a width <= 0.

    """
    check_positive("width_m", width_m, "m")
    alpha = np.atleast_1d(np.asarray(rake_angle_rad, dtype=float))
    depth = np.atleast_1d(np.asarray(depth_m, dtype=float))
    good_alpha = (alpha > 0.0) & (alpha < np.pi)
    if not np.all(good_alpha):
        raise InvalidInputError("rake_angle_rad", float(alpha[np.argmin(good_alpha)]), "must lie in (0, pi)", "rad")
    good_depth = np.isfinite(depth) & (depth >= 0.0)
    if not np.all(good_depth):
        raise InvalidInputError("depth_m", float(depth[np.argmin(good_depth)]), "must be finite and >= 0", "m")
    alpha, depth = np.broadcast_arrays(alpha, depth)
    beta = failure_plane_angle(soil, gravity, alpha, np.maximum(depth, 1e-9))
    push = width_m * force_on_plane(soil, gravity, alpha, depth, beta)
    adhesion = width_m * soil.adhesion_Pa * depth / np.sin(alpha)
    delta = soil.tool_friction_angle_rad
    along = push * np.sin(alpha + delta) + adhesion * np.cos(alpha)
    up = push * np.cos(alpha + delta) - adhesion * np.sin(alpha)
    return -along, -up


def tool_force_world(
    soil: SoilProperties,
    gravity: float,
    rake_angle_rad: ArrayLike,
    depth_m: ArrayLike,
    width_m: float,
    travel_sign: ArrayLike,
) -> Array:
    """The soil's force on the tool in the world plane (T, 2) [N], for a horizontal soil surface.

    ``travel_sign`` +1 or -1 per sample: the tool travels along +x or -x of the world (an excavator
    drags its tool towards the machine, -x when the machine faces +x); ``rake_angle_rad`` is
    measured from the surface on the side the tool travels to. A depth of 0 (tool above ground)
    gives no force.
    """
    sign = np.atleast_1d(np.asarray(travel_sign, dtype=float))
    if not np.all(np.abs(sign) == 1.0):
        raise InvalidInputError("travel_sign", str(np.unique(sign)), "must be +1 or -1 per sample")
    along, up = blade_force(soil, gravity, rake_angle_rad, depth_m, width_m)
    along, up, sign = np.broadcast_arrays(along, up, sign)
    return np.stack([sign * along, up], axis=-1)

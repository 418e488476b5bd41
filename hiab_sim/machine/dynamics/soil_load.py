"""The soil's force on the TCP (the bucket tip) along a sampled reference, for an optimiser.

Given the tip positions p = (x, y), velocities v and the TCP angle theta (the world angle of the
bucket frame's x axis, hinge -> tip) at T samples, a horizontal ground at ``y_ground`` and a bucket
of width w, the force [N] of the soil on the tip in the world frame, (T, 2), is

    F = W(d, v_x) F_FEE(alpha, d, u),     d = y_ground - y  (the cut depth, 0 above ground),

with F_FEE the fundamental earthmoving equation of :mod:`hiab_sim.machine.dynamics.soil`
(``tool_force_world``: McKyes 1985, ch. 4; Blouin et al. 2001), evaluated as a flat blade from the
tip to the bucket hinge:

* travel direction u = sign(v_x): the cut of a horizontal soil surface is along the horizontal
  component of the tip's velocity (the model has no penetration term; vertical motion alone cuts
  nothing);
* rake angle alpha, the blade's angle from the surface on the side the tip travels to: the blade
  runs from the tip to the hinge, along -(cos theta, sin theta), and the soil model's blade leans
  back along (-cos alpha, sin alpha) in the cutting frame (x along u, y up), so
  alpha = atan2(-sin theta, u cos theta); alpha lies in (0, pi) when the hinge is above the tip;
* W = S(d / ONSET_DEPTH_M) S((|v_x| - DEAD_SPEED_M_S) / (ONSET_SPEED_M_S - DEAD_SPEED_M_S)), S the
  quintic smoothstep
  S(s) = 6 s^5 - 15 s^4 + 10 s^3 on [0, 1] (0 below, 1 above), whose first and second derivatives
  vanish at both ends. The FEE force already grows from zero with the depth (cohesion and adhesion
  terms ~ d, weight ~ d^2); the depth factor makes the entry C2 in time (no step, no kink where the
  tip crosses the ground), and the speed factor makes the force vanish C2-smoothly where the
  horizontal travel reverses (where u, and with it the rake's reference side, flips); below
  1 mm/s there is no force at all (the noise of differentiated positions). Past 10 mm of depth
  and 20 mm/s of horizontal speed W = 1 and F is soil.py's force exactly.

Above the ground (d <= 0) and at rest the force is exactly zero. The model is quasi-static (no
soil inertia) and cuts a fresh horizontal surface: it is the cutting resistance of the drag and
the shallow part of the curl, not the filling of the bucket or the weight of its payload.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_positive, check_range
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.soil import SoilProperties, tool_force_world

#: Depth over which the force is blended in [m]: chosen small against the cuts of the excavator's
#: cycles (30-120 mm) so that it changes the cutting force only in the first 10 mm of entry.
ONSET_DEPTH_M = 0.01
#: Horizontal tip speed below which the force is blended out [m/s]: chosen small against the cut
#: speeds of the cycles (peaks 0.1-0.5 m/s), so only the start and stop of a drag are affected.
ONSET_SPEED_M_S = 0.02
#: Horizontal tip speed below which there is no force at all [m/s]: chosen above the noise of tip
#: positions rounded to 10 um and differentiated at 50 Hz (central differences: 0.25 mm/s), so that a
#: tip at rest or moving straight up never cuts on its noise (e.g. backwards, where alpha is out of range).
DEAD_SPEED_M_S = 0.001


def smoothstep(s: ArrayLike) -> Array:
    """Quintic smoothstep 6 s^5 - 15 s^4 + 10 s^3 of s clipped to [0, 1] (C2: S' = S'' = 0 at both ends)."""
    x = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
    return np.asarray(x**3 * (10.0 + x * (-15.0 + 6.0 * x)))


def _samples(position: ArrayLike, velocity: ArrayLike, tcp_angle: ArrayLike) -> tuple[Array, Array, Array]:
    p = np.asarray(position, dtype=float)
    v = np.asarray(velocity, dtype=float)
    theta = np.asarray(tcp_angle, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2:
        raise InvalidInputError("position", f"shape {p.shape}", "must be (T, 2): tip x, y [m]")
    if v.shape != p.shape:
        raise InvalidInputError("velocity", f"shape {v.shape}", f"must match position {p.shape}")
    if theta.shape != p.shape[:1]:
        raise InvalidInputError("tcp_angle", f"shape {theta.shape}", f"must be ({p.shape[0]},)")
    for name, a in (("position", p), ("velocity", v), ("tcp_angle", theta)):
        if not np.all(np.isfinite(a)):
            raise InvalidInputError(name, "a non-finite entry", "must be finite")
    return p, v, theta


def cutting_state(
    position: ArrayLike, velocity: ArrayLike, tcp_angle: ArrayLike, y_ground: float
) -> tuple[Array, Array, Array, Array]:
    """Per sample: depth d [m] (0 above ground), travel sign u, rake angle alpha [rad] and blend W in [0, 1].

    See the module docstring for the formulas; alpha is given for every sample (it matters only
    where W > 0).
    """
    check_range("y_ground", y_ground, unit="m")
    p, v, theta = _samples(position, velocity, tcp_angle)
    depth = np.maximum(y_ground - p[:, 1], 0.0)
    travel = np.where(v[:, 0] < 0.0, -1.0, 1.0)
    rake = np.arctan2(-np.sin(theta), travel * np.cos(theta))
    speed = (np.abs(v[:, 0]) - DEAD_SPEED_M_S) / (ONSET_SPEED_M_S - DEAD_SPEED_M_S)
    blend = smoothstep(depth / ONSET_DEPTH_M) * smoothstep(speed)
    return depth, travel, rake, blend


def soil_force_on_tcp(
    position: ArrayLike,
    velocity: ArrayLike,
    tcp_angle: ArrayLike,
    *,
    y_ground: float,
    width_m: float,
    soil: SoilProperties,
    gravity: float,
) -> Array:
    """Force of the soil on the TCP in the world frame, (T, 2) [N] (the module docstring's F).

    Args:
        position: Tip positions (T, 2) [m] in the world (machine) frame, y up.
        velocity: Tip velocities (T, 2) [m/s].
        tcp_angle: World angle of the bucket frame's x axis (hinge -> tip), (T,) [rad].
        y_ground: Height of the horizontal ground surface [m].
        width_m: Bucket (cutting edge) width [m] > 0.
        soil: The soil's data (:mod:`hiab_sim.machine.dynamics.soil_file` reads them from a file).
        gravity: Gravitational acceleration [m/s^2] > 0 (the machine file's).

    Raises:
        InvalidInputError: badly shaped or non-finite samples, a width or gravity <= 0, or a
            sample that cuts (W > 0) with the hinge not above the tip (rake angle outside (0, pi))
            or too steep for a failure wedge (alpha + delta + phi >= pi), naming ``tcp_angle``.

    """
    check_positive("width_m", width_m, "m")
    check_positive("gravity", gravity, "m/s^2")
    depth, travel, rake, blend = cutting_state(position, velocity, tcp_angle, y_ground)
    force = np.zeros((depth.size, 2))
    active = np.flatnonzero(blend > 0.0)
    if active.size == 0:
        return force
    a = rake[active]
    top = np.pi - soil.tool_friction_angle_rad - soil.friction_angle_rad
    bad = (a <= 0.0) | (a >= top)
    if np.any(bad):
        k = int(active[np.argmax(bad)])
        raise InvalidInputError(
            "tcp_angle",
            float(np.asarray(tcp_angle, dtype=float)[k]),
            f"sample {k} cuts the soil with rake angle {a[np.argmax(bad)]:.4g} rad; it must lie in"
            f" (0, {top:.4g}) (hinge above the tip; alpha + delta + phi < pi)",
            "rad",
        )
    force[active] = blend[active, None] * tool_force_world(soil, gravity, a, depth[active], width_m, travel[active])
    return force

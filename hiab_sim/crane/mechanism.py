"""Closed-chain trigonometry of one lift/tilt chain (seed eqs. qus .. DDthetas), numpy only.

The chain is a triangle with vertices at the cylinder base pivot {Bc}, the boom hinge {B1} and
the rod-end pivot {Tc}; its sides are ``L`` ({Bc}-{B1}), ``L1`` ({B1}-{Tc}) and the pin-to-pin
length ``s = x + x0`` of the actuator, x0 = Lc + Lc0. The internal angles follow the seed's
convention (eq. qus): each is minus the triangle's interior angle, ``q`` at the boom hinge,
``q1`` at the cylinder base, ``q2`` at the rod end, so q, q1, q2 lie in (-pi, 0) and
q + q1 + q2 = -pi (eq. triangle, const_l).

Joint angle. hiab-sim's joints ``theta1``/``theta2`` are the source's (Petrovic & Mattila 2022):
counter-clockwise positive, extension lifts the boom. The boom's rotation relative to {Bc} is
``theta - joint_offset`` (XS 031: q1 = theta1 - pi/2 - beta1 - beta2 and q2 = theta2 - beta3 -
beta4 in the source's notation), and it equals interior angle - pi = -pi - q. Hence

    theta = psi - q,   psi = joint_offset - pi,

which is the seed's eq. thetas (theta = q + psi) with the opposite sign of q: with the source's
sign of theta, eqs. Dthetas and DDthetas read dtheta = -dq and ddtheta = -ddq.

Velocity ratios (eq. k1_3): dq = k1 dx, dq1 = k2 dx, dq2 = k3 dx with

    k1 = s / (L L1 sin q)          (the seed prints -s / (L L1 sin q): a sign slip; with
                                     q = -arccos(.) of eq. qus_a, dq/dx has the sign of 1/sin q)
    k2 = -(s - L cos q1) / (s L sin q1)
    k3 = -(s - L1 cos q2) / (s L1 sin q2)

and k1 + k2 + k3 = 0 follows from the triangle property. Every function is vectorised over time
samples (any array shape); lengths in [m], angles in [rad], time derivatives per second.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import ChainLengths, ClosedChain, Crane, LinkLengths, check_positive_lengths
from hiab_sim.errors import InvalidInputError

#: Slack on stroke bounds [m]: joint ranges computed from x = 0 must not fail by round-off.
STROKE_TOLERANCE = 1e-12


def triangle_angles(x: ArrayLike, L: float, L1: float, x0: float) -> tuple[Array, Array, Array]:
    """Internal angles (q, q1, q2) of the chain's triangle at stroke x (seed eq. qus) [rad].

    Cosines are clipped to [-1, 1] against round-off at a flat triangle; whether a stroke is
    admissible is decided by :func:`check_joint_samples`, not here.
    """
    s = np.asarray(x, dtype=float) + x0
    q = -np.arccos(np.clip((s**2 - L**2 - L1**2) / (-2.0 * L * L1), -1.0, 1.0))
    q1 = -np.arccos(np.clip((L1**2 - s**2 - L**2) / (-2.0 * s * L), -1.0, 1.0))
    q2 = -np.arccos(np.clip((L**2 - s**2 - L1**2) / (-2.0 * s * L1), -1.0, 1.0))
    return q, q1, q2


def stroke_from_hinge_angle(q: ArrayLike, L: float, L1: float, x0: float) -> Array:
    """Stroke x from the internal angle q at the boom hinge (inverse of eq. qus_a) [m]."""
    q = np.asarray(q, dtype=float)
    return np.sqrt(L**2 + L1**2 - 2.0 * L * L1 * np.cos(q)) - x0


def velocity_ratios(x: ArrayLike, L: float, L1: float, x0: float) -> tuple[Array, Array, Array]:
    """Velocity ratios (k1, k2, k3) = d(q, q1, q2)/dx (eqs. dq__, k1_3) [rad/m]."""
    s = np.asarray(x, dtype=float) + x0
    q, q1, q2 = triangle_angles(x, L, L1, x0)
    k1 = s / (L * L1 * np.sin(q))
    k2 = -(s - L * np.cos(q1)) / (s * L * np.sin(q1))
    k3 = -(s - L1 * np.cos(q2)) / (s * L1 * np.sin(q2))
    return k1, k2, k3


def velocity_ratio_rates(x: ArrayLike, dx: ArrayLike, L: float, L1: float, x0: float) -> tuple[Array, Array, Array]:
    """Time derivatives (dk1, dk2, dk3) of the velocity ratios (used in eq. 04) [rad/(m s)].

    Each is dk/dt = (dk/dx) dx, with dk/dx from differentiating eq. k1_3 and using
    dq = k1 dx, dq1 = k2 dx, dq2 = k3 dx.
    """
    dx = np.asarray(dx, dtype=float)
    s = np.asarray(x, dtype=float) + x0
    q, q1, q2 = triangle_angles(x, L, L1, x0)
    k1, k2, k3 = velocity_ratios(x, L, L1, x0)
    dk1_dx = (np.sin(q) - s * np.cos(q) * k1) / (L * L1 * np.sin(q) ** 2)
    dk2_dx = _side_ratio_slope(s, L, q1, k2)
    dk3_dx = _side_ratio_slope(s, L1, q2, k3)
    return dk1_dx * dx, dk2_dx * dx, dk3_dx * dx


def _side_ratio_slope(s: Array, side: float, angle: Array, k: Array) -> Array:
    """d/dx of k = -(s - side cos a) / (s side sin a), with da/dx = k."""
    numerator = s - side * np.cos(angle)
    denominator = s * side * np.sin(angle)
    d_numerator = 1.0 + side * np.sin(angle) * k
    d_denominator = side * np.sin(angle) + s * side * np.cos(angle) * k
    return -(d_numerator * denominator - numerator * d_denominator) / denominator**2


# ---------------------------------------------------------------------------------------------
# Joint angle theta <-> stroke x of a configured chain
# ---------------------------------------------------------------------------------------------


def hinge_angle(chain: ClosedChain, theta: ArrayLike) -> Array:
    """Internal angle q at the boom hinge from the joint angle: q = psi - theta, psi = offset - pi."""
    return chain.joint_offset - np.pi - np.asarray(theta, dtype=float)


def boom_rotation(chain: ClosedChain, theta: ArrayLike) -> Array:
    """The source's boom rotation relative to {Bc}: theta - joint_offset [rad].

    XS 031: q1 = theta1 - pi/2 - beta1 - beta2 (lift), q2 = theta2 - beta3 - beta4 (tilt).
    """
    return np.asarray(theta, dtype=float) - chain.joint_offset


def joint_to_stroke(chain: ClosedChain, lengths: ChainLengths, theta: ArrayLike) -> Array:
    """Actuator stroke x for joint angle theta (eqs. thetas, qus_a) [m]."""
    return stroke_from_hinge_angle(hinge_angle(chain, theta), lengths.L, chain.L1, lengths.x0)


def joint_to_stroke_partials(chain: ClosedChain, lengths: ChainLengths, theta: ArrayLike) -> tuple[Array, Array]:
    """Partials of :func:`joint_to_stroke`: (dx/dtheta [m/rad], dx/d(L, Lc0, Lc) [-], shape (..., 3)).

    With q = psi - theta and s = sqrt(L^2 + L1^2 - 2 L L1 cos q) (eq. qus_a), x = s - x0, so
    dx/dtheta = -L L1 sin q / s (= -1 / k1 of eq. k1_3), dx/dL = (L - L1 cos q) / s and
    dx/dLc0 = dx/dLc = -1 (x0 = Lc0 + Lc).
    """
    q = hinge_angle(chain, theta)
    L, L1 = lengths.L, chain.L1
    s = np.sqrt(L**2 + L1**2 - 2.0 * L * L1 * np.cos(q))
    d_theta = -L * L1 * np.sin(q) / s
    d_lengths = np.stack([(L - L1 * np.cos(q)) / s, -np.ones_like(q), -np.ones_like(q)], axis=-1)
    return d_theta, d_lengths


def stroke_to_joint(chain: ClosedChain, lengths: ChainLengths, x: ArrayLike) -> Array:
    """Joint angle theta for actuator stroke x (eqs. qus_a, thetas) [rad]."""
    q, _, _ = triangle_angles(x, lengths.L, chain.L1, lengths.x0)
    return chain.joint_offset - np.pi - q


def joint_to_actuator(
    chain: ClosedChain, lengths: ChainLengths, theta: ArrayLike, dtheta: ArrayLike, ddtheta: ArrayLike
) -> tuple[Array, Array, Array]:
    """Actuator position, velocity, acceleration (x, dx, ddx) from the joint's (eqs. dq__, 04).

    With dtheta = -dq = -k1 dx and ddtheta = -(dk1 dx + k1 ddx).
    """
    x = joint_to_stroke(chain, lengths, theta)
    k1, _, _ = velocity_ratios(x, lengths.L, chain.L1, lengths.x0)
    dx = -np.asarray(dtheta, dtype=float) / k1
    dk1, _, _ = velocity_ratio_rates(x, dx, lengths.L, chain.L1, lengths.x0)
    ddx = (-np.asarray(ddtheta, dtype=float) - dk1 * dx) / k1
    return x, dx, ddx


def actuator_to_joint(
    chain: ClosedChain, lengths: ChainLengths, x: ArrayLike, dx: ArrayLike, ddx: ArrayLike
) -> tuple[Array, Array, Array]:
    """Joint angle, velocity, acceleration (theta, dtheta, ddtheta) from the actuator's (eqs. 04, DDthetas)."""
    dx = np.asarray(dx, dtype=float)
    k1, _, _ = velocity_ratios(x, lengths.L, chain.L1, lengths.x0)
    dk1, _, _ = velocity_ratio_rates(x, dx, lengths.L, chain.L1, lengths.x0)
    theta = stroke_to_joint(chain, lengths, x)
    return theta, -k1 * dx, -(dk1 * dx + k1 * np.asarray(ddx, dtype=float))


def stroke_bounds(chain: ClosedChain, lengths: ChainLengths) -> tuple[float, float]:
    """Usable stroke interval [x_min, x_max] [m] from the stroke and the triangle inequality.

    x in [0, min(stroke, Lc)] (const_j) and |L - L1| < x + x0 < L + L1 (const_k and its
    lower counterpart). The triangle ends are singular (sin q = 0): they are open bounds.
    """
    x_min = max(0.0, abs(lengths.L - chain.L1) - lengths.x0)
    x_max = min(chain.stroke, lengths.Lc, lengths.L + chain.L1 - lengths.x0)
    return x_min, x_max


def reachable_joint_range(chain: ClosedChain, lengths: ChainLengths) -> tuple[float, float]:
    """Joint range [theta_min, theta_max] [rad] reachable within :func:`stroke_bounds`.

    theta increases with x (the joint velocity ratio -k1 is positive), so the range maps the
    stroke bounds. Raises :class:`InvalidInputError` if no stroke is usable.
    """
    x_min, x_max = stroke_bounds(chain, lengths)
    if not x_min < x_max:
        raise InvalidInputError(
            f"{chain.name}.Lc0 + Lc",
            lengths.x0,
            f"leaves no usable stroke: need |L - L1| < Lc0 + x + Lc < L + L1 for some x in [0, {chain.stroke:.6g}]",
            "m",
        )
    theta = stroke_to_joint(chain, lengths, np.array([x_min, x_max]))
    return float(theta[0]), float(theta[1])


def check_joint_samples(chain: ClosedChain, lengths: ChainLengths, theta: ArrayLike, field: str | None = None) -> None:
    """Raise :class:`InvalidInputError` if any joint sample leaves the chain's usable stroke.

    A sample is valid when q lies strictly inside (-pi, 0) (the triangle is not flat, so the
    ratios of eq. k1_3 exist) and its stroke x lies in [0, min(stroke, Lc)] (const_j, const_k).
    """
    name = field or chain.name
    theta = np.asarray(theta, dtype=float)
    if not np.all(np.isfinite(theta)):
        raise InvalidInputError(name, "NaN or inf", "joint samples must be finite", "rad")
    q = hinge_angle(chain, theta)
    x = stroke_from_hinge_angle(q, lengths.L, chain.L1, lengths.x0)
    x_min, x_max = stroke_bounds(chain, lengths)
    bad = (q <= -np.pi) | (q >= 0.0) | (x < x_min - STROKE_TOLERANCE) | (x > x_max + STROKE_TOLERANCE)
    if np.any(bad):
        worst = float(theta.reshape(-1)[np.argmax(bad.reshape(-1))])
        at = f"{chain.name} L / Lc0 / Lc = {lengths.L:.6g} / {lengths.Lc0:.6g} / {lengths.Lc:.6g} m"
        try:
            low, high = reachable_joint_range(chain, lengths)
            allowed = f"must lie in [{low:.6g}, {high:.6g}] rad, the stroke [{x_min:.6g}, {x_max:.6g}] m at {at}"
        except InvalidInputError:
            allowed = f"no stroke is usable at {at}"
        raise InvalidInputError(name, worst, allowed, "rad")


def check_lengths(crane: Crane, lengths: LinkLengths) -> None:
    """Raise :class:`InvalidInputError` unless every chain can serve its working joint range.

    Checks, per chain: finite, positive L, Lc0, Lc (const_g); the stroke inside [0, Lc]
    (const_j); and over the working range of theta the stroke x inside [0, stroke] and the
    triangle strict, |L - L1| < Lc0 + x + Lc < L + L1 (const_k), so that sin q != 0 and the
    velocity ratios k1..k3 (eq. k1_3) are defined.
    """
    check_positive_lengths(lengths)
    for chain, xi in zip(crane.chains, lengths, strict=True):
        if chain.stroke > xi.Lc:
            raise InvalidInputError(
                f"{chain.name}.stroke", chain.stroke, f"must lie in [0, Lc] = [0, {xi.Lc:.6g}] m", "m"
            )
        check_joint_samples(chain, xi, np.asarray(chain.joint_range), field=f"{chain.name}.joint_range")

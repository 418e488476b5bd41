"""Forward kinematics: loop closure and link-length independence of the TCP."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane import kinematics
from hiab_sim.crane.description import ChainLengths, Crane, LinkLengths
from hiab_sim.crane.loader import load_crane

CRANE = load_crane("xs031")


def _samples(n: int = 25) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 1.0, n)
    (l1, h1), (l2, h2) = CRANE.lift.joint_range, CRANE.tilt.joint_range
    return l1 + (h1 - l1) * (0.1 + 0.8 * t), l2 + (h2 - l2) * (0.9 - 0.8 * t), 0.2 + 0.5 * t


@settings(max_examples=30, deadline=None)
@given(st.floats(0.95, 1.1), st.floats(0.6, 1.0), st.floats(0.95, 1.1), st.floats(0.6, 1.0))
def test_rod_end_meets_the_boom_pivot_and_tcp_ignores_lengths(a: float, b: float, c: float, d: float) -> None:
    """const_m: the rod's end {T2} coincides with the boom's {T1}; the TCP is length-independent."""
    default = CRANE.default_lengths
    lengths = LinkLengths(
        ChainLengths(default.lift.L * a, 0.085, 0.745 * b),
        ChainLengths(default.tilt.L * c, 0.085, 0.745 * d),
    )
    theta1, theta2, xt2 = np.array([0.6]), np.array([-1.3]), np.array([0.4])
    frames = kinematics.forward_kinematics(CRANE, lengths, theta1, theta2, xt2)
    for chain in CRANE.chains:
        on_rod = frames.point(f"{chain.name}_rod", [getattr(lengths, chain.name).Lc, 0.0, 0.0])
        on_boom = frames.point(f"{chain.name}_boom", [chain.L1, 0.0, 0.0])
        np.testing.assert_allclose(on_rod, on_boom, atol=1e-12)
    reference = kinematics.tcp_position(CRANE, theta1, theta2, xt2)
    np.testing.assert_allclose(frames.position["tcp"], reference, atol=1e-12)


def test_loop_closes_along_the_working_range(crane: Crane) -> None:
    """Loop closure holds for the default lengths over a sweep of all three joints."""
    frames = kinematics.forward_kinematics(crane, crane.default_lengths, *_samples())
    for chain in crane.chains:
        on_rod = frames.point(f"{chain.name}_rod", [chain.default_lengths.Lc, 0.0, 0.0])
        on_boom = frames.point(f"{chain.name}_boom", [chain.L1, 0.0, 0.0])
        np.testing.assert_allclose(on_rod, on_boom, atol=1e-12)


def test_tcp_moves_out_along_the_telescope_axis(crane: Crane) -> None:
    """d(TCP)/d(xt2) is the unit telescope axis, which lies in the plane of motion."""
    theta1, theta2 = np.array([0.6]), np.array([-1.3])
    p0 = kinematics.tcp_position(crane, theta1, theta2, np.array([0.3]))
    p1 = kinematics.tcp_position(crane, theta1, theta2, np.array([0.4]))
    step = (p1 - p0)[0] / 0.1
    assert abs(np.linalg.norm(step) - 1.0) < 1e-12
    assert abs(step[2]) < 1e-12

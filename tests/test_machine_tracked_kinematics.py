"""Generic tracked TCP kinematics: the crane's closed form, finite differences, forward kinematics, IK round trips."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane.description import Crane
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Link, Machine, Pose, RigidBody, mat3, rot_z
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine.kinematics.tracked import TrackedKinematics, TrackedSamples, inverse_kinematics
from hiab_sim.machine.loader import load_machine
from hiab_sim.study.motion.trajectory import TcpKinematics

FIELDS = ("position", "velocity", "acceleration", "d_position", "d_velocity", "d_acceleration")


def _rot_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _mixed_machine() -> Machine:
    """R-P-R-R chain on a shifted, turned root, a prismatic frame tilted out of the plane, a side branch.

    The slide's frame is Rz(0.4) Rx(0.3): its x axis stays in the plane, its z axis does not, so the
    next joint frame turns back by Rx(-0.3) (its z axis is the plane normal again).
    """
    body = RigidBody("body", 1.0, (0.1, 0.0, 0.0), mat3(np.diag([0.01, 0.01, 0.02])))
    tilt = 0.3
    slide_r = rot_z(0.4) @ _rot_x(tilt)
    elbow_r = _rot_x(-tilt) @ np.asarray(rot_z(-0.7))
    links = (
        Link("ground", None, "mount", "fixed", Pose((0.3, -0.2, 0.05), rot_z(0.25)), None),
        Link("turret", "ground", "swing", "revolute", Pose((0.1, 0.4, 0.02), rot_z(-0.5)), (-1.0, 1.0), (body,)),
        Link("carriage", "turret", "slide", "prismatic", Pose((0.8, 0.1, 0.03), mat3(slide_r)), (0.0, 0.6), (body,)),
        Link(
            "forearm", "carriage", "elbow", "revolute", Pose((0.5, 0.2, 0.1), mat3(elbow_r)), (-1.5, 0.5), (body,)
        ),  # J is singular near 0.8 rad
        Link("hand", "forearm", "wrist", "revolute", Pose((0.7, -0.1, 0.0), rot_z(0.3)), (-1.0, 1.0), (body,)),
        Link("mirror", "turret", "side", "revolute", Pose((0.2, 0.0, 0.0)), (-1.0, 1.0), (body,)),
    )
    return Machine("mixed chain", "test", 9.81, links, (), "hand", Pose((0.4, 0.15, -0.02), rot_z(-0.6)))


MACHINES = {
    "xs031": (lambda: load_machine("xs031"), ("xt2",)),
    "exact": (lambda: load_machine("exact"), ("tcp_angle",)),
    "mixed": (_mixed_machine, ("tcp_angle", "slide", "side")),
}


@pytest.fixture(scope="module", params=sorted(MACHINES))
def tracked(request: pytest.FixtureRequest) -> TrackedKinematics:
    """The tracked kinematics of each test machine."""
    build, extra = MACHINES[request.param]
    return TrackedKinematics(build(), extra)


def _states(machine: Machine, rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random joint states within the working ranges, rates of order 1 rad/s or m/s."""
    ranges = [machine.joint_link(j).joint_range for j in machine.joint_names]
    q = np.stack([rng.uniform(lo, hi, n) for lo, hi in ranges], axis=-1)  # type: ignore[misc]
    return q, rng.uniform(-1.0, 1.0, q.shape), rng.uniform(-2.0, 2.0, q.shape)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_xs031_equals_the_crane_closed_form(crane: Crane, seed: int) -> None:
    """On the XS 031 file with xt2 tracked, every sample and partial equals the crane's TcpKinematics to 1e-12."""
    machine = load_machine("xs031")
    kin, ref = TrackedKinematics(machine, ("xt2",)), TcpKinematics(crane)
    q, dq, ddq = _states(machine, np.random.default_rng(seed), 8)
    ours, theirs = kin.samples(q, dq, ddq), ref.samples(q, dq, ddq)
    for name in FIELDS:
        np.testing.assert_allclose(getattr(ours, name), getattr(theirs, name), rtol=0, atol=1e-12, err_msg=name)
    np.testing.assert_allclose(kin.position(q), ref.position(q), rtol=0, atol=1e-12)
    assert kin.names == ("x_tcp", "y_tcp", "xt2")
    assert kin.z == pytest.approx(ref.z, abs=1e-15)


def test_point_and_angle_agree_with_forward_kinematics(tracked: TrackedKinematics) -> None:
    """TCP (x, y, z) and tcp_angle equal the 3D frame composition of forward_kinematics."""
    machine = tracked.machine
    q, dq, ddq = _states(machine, np.random.default_rng(3), 50)
    frames = forward_kinematics(machine, q)
    np.testing.assert_allclose(tracked.position(q), frames.tcp_position, rtol=0, atol=1e-12)
    np.testing.assert_allclose(frames.tcp_position[:, 2], tracked.z, rtol=0, atol=1e-12)
    s = tracked.samples(q, dq, ddq)
    np.testing.assert_allclose(s.position[:, :2], frames.tcp_position[:, :2], rtol=0, atol=1e-12)
    if "tcp_angle" in tracked.names:
        row = tracked.names.index("tcp_angle")
        world = np.arctan2(frames.tcp_rotation[:, 1, 0], frames.tcp_rotation[:, 0, 0])
        np.testing.assert_allclose(np.angle(np.exp(1j * (s.position[:, row] - world))), 0.0, atol=1e-12)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(sorted(MACHINES)))
def test_partials_match_central_differences(seed: int, name: str) -> None:
    """Every column of d_position, d_velocity, d_acceleration equals a central difference (h = 1e-6)."""
    build, extra = MACHINES[name]
    machine = build()
    kin = TrackedKinematics(machine, extra)
    state = np.concatenate(_states(machine, np.random.default_rng(seed), 4), axis=1)  # (T, 3n)
    n, h = kin.n, 1e-6
    s = kin.samples(state[:, :n], state[:, n : 2 * n], state[:, 2 * n :])
    for j in range(3 * n):
        plus, minus = state.copy(), state.copy()
        plus[:, j] += h
        minus[:, j] -= h
        sp = kin.samples(plus[:, :n], plus[:, n : 2 * n], plus[:, 2 * n :])
        sm = kin.samples(minus[:, :n], minus[:, n : 2 * n], minus[:, 2 * n :])
        for value, partial in (
            ("position", "d_position"),
            ("velocity", "d_velocity"),
            ("acceleration", "d_acceleration"),
        ):
            fd = (getattr(sp, value) - getattr(sm, value)) / (2.0 * h)
            np.testing.assert_allclose(getattr(s, partial)[:, :, j], fd, rtol=0, atol=2e-8, err_msg=f"{partial}[{j}]")


def _smooth_trajectory(machine: Machine, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q(t) = mid + amp sin(w t + phase) per joint, within the ranges, and its exact rates."""
    ranges = np.array([machine.joint_link(j).joint_range for j in machine.joint_names])
    mid, amp = ranges.mean(axis=1), 0.3 * np.diff(ranges, axis=1)[:, 0]
    w = 1.3 + 0.4 * np.arange(len(mid))  # rad/s, distinct per joint
    phase = 0.7 * np.arange(len(mid))
    arg = np.outer(t, w) + phase
    return mid + amp * np.sin(arg), amp * w * np.cos(arg), -amp * w**2 * np.sin(arg)


def test_rates_are_time_derivatives_along_a_trajectory(tracked: TrackedKinematics) -> None:
    """Velocity = d position/dt and acceleration = d velocity/dt by central differences in time."""
    machine = tracked.machine
    t, h = np.linspace(0.0, 3.0, 31), 1e-5
    s = tracked.samples(*_smooth_trajectory(machine, t))
    plus, minus = (
        tracked.samples(*_smooth_trajectory(machine, t + h)),
        tracked.samples(*_smooth_trajectory(machine, t - h)),
    )
    np.testing.assert_allclose(s.velocity, (plus.position - minus.position) / (2 * h), rtol=0, atol=1e-8)
    np.testing.assert_allclose(s.acceleration, (plus.velocity - minus.velocity) / (2 * h), rtol=0, atol=1e-8)
    xyz = [tracked.position(_smooth_trajectory(machine, x)[0]) for x in (t + h, t - h)]
    np.testing.assert_allclose(s.velocity[:, :2], (xyz[0] - xyz[1])[:, :2] / (2 * h), rtol=0, atol=1e-8)


@pytest.mark.parametrize("name", ["exact", "xs031", "mixed"])
def test_inverse_kinematics_round_trip(name: str) -> None:
    """Forward samples of a joint trajectory, then inverse kinematics from a perturbed guess, recover q, dq, ddq."""
    build, extra = MACHINES[name]
    machine = build()
    kin = TrackedKinematics(machine, extra)
    q, dq, ddq = _smooth_trajectory(machine, np.linspace(0.0, 2.0, 41))
    s = kin.samples(q, dq, ddq)
    got = inverse_kinematics(kin, s.position, s.velocity, s.acceleration, q[0] + 0.05)
    for want, have in zip((q, dq, ddq), got, strict=True):
        np.testing.assert_allclose(have, want, rtol=0, atol=1e-9)


def test_inverse_kinematics_names_an_unreachable_sample() -> None:
    """A TCP point beyond the arm's reach raises InvalidInputError on ``reference`` naming the sample."""
    kin = TrackedKinematics(load_machine("exact"), ("tcp_angle",))
    q, dq, ddq = _smooth_trajectory(load_machine("exact"), np.linspace(0.0, 1.0, 5))
    s = kin.samples(q, dq, ddq)
    far = s.position.copy()
    far[3, 0] += 10.0  # m: the boom, arm and bucket reach 3.7 m at most
    with pytest.raises(InvalidInputError, match="sample 3") as info:
        inverse_kinematics(kin, far, s.velocity, s.acceleration, q[0])
    assert info.value.field == "reference"


@pytest.mark.parametrize(
    ("name", "extra"),
    [
        ("exact", ("delta",)),  # unknown joint
        ("exact", ("tcp_angle", "gamma")),  # one too many
        ("exact", ()),  # one too few
        ("xs031", ("x_tcp",)),  # the point coordinates are not extras
        ("mixed", ("tcp_angle", "slide", "slide")),  # repeated
        ("mixed", ("tcp_angle", "slide", "elbow")),  # the side joint does not move the TCP and is left out
        ("xs031", "xt2"),  # a string, not a list of names
    ],
)
def test_bad_tracked_names_are_refused(name: str, extra: tuple[str, ...]) -> None:
    """Unknown, repeated or miscounted extra coordinates raise InvalidInputError naming ``tracked``."""
    with pytest.raises(InvalidInputError) as info:
        TrackedKinematics(MACHINES[name][0](), extra)
    assert info.value.field == "tracked"


def test_samples_are_validated_when_built() -> None:
    """TrackedSamples refuses partials whose shape does not match the coordinates."""
    ok = np.zeros((2, 3))
    with pytest.raises(InvalidInputError) as info:
        TrackedSamples(ok, ok, ok, np.zeros((2, 3, 9)), np.zeros((2, 3, 8)), np.zeros((2, 3, 9)))
    assert info.value.field == "samples.d_velocity"

"""Reference kinds: the spiral wrapper, pick-and-place paths, closed-form IK and reachability errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from references_helper import pick_and_place_tasks

from hiab_sim.crane import kinematics
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import DEFAULT_STUDY, shipped
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.motion.workspace import initial_joints, planar_ik
from hiab_sim.study.references.kinds import PickAndPlace, Spiral, reference_from_mapping, septic_law
from hiab_sim.study.spec.study_file import load_study
from hiab_sim.study.spec.tasks import column_names

STUDY = load_study()
CRANE = STUDY.crane
NAMES = column_names(STUDY.model)
KIN = tr.TcpKinematics(CRANE)
#: Low near the crane base to far out over a 1.2 m high obstacle (the duty-mix study's task).
TASK = PickAndPlace(
    pick=(1.6, -1.2), place=(3.6, 0.2), clearance=0.8, telescope=(0.1, 0.8), move_time=10.0, dwell=(1.5, 1.5)
)


def test_spiral_from_the_default_study_block_is_the_loaders_spiral() -> None:
    """The default study's reference block read as a ``spiral`` kind is the loader's reference."""
    default = shipped("study", DEFAULT_STUDY)
    block = yaml.safe_load(default.read_text())["reference"]
    spiral = reference_from_mapping(block, "reference", Path(str(default.file)).parent, STUDY.grid.duration, NAMES)
    assert isinstance(spiral, Spiral) and spiral.duration == STUDY.grid.duration
    assert spiral == STUDY.reference  # the loader reads the single reference with the same kind


def test_closed_form_ik_puts_the_foundation_tcp_on_the_point() -> None:
    """FK (crane.kinematics) of the closed-form IK joints returns the requested TCP points."""
    rng = np.random.default_rng(3)
    q = np.column_stack([rng.uniform(0.0, 1.6, 50), rng.uniform(-2.3, -0.2, 50), rng.uniform(0.0, 1.1, 50)])
    p = kinematics.tcp_position(CRANE, q[:, 0], q[:, 1], q[:, 2])
    ik = planar_ik(KIN, CRANE, p[:, :2], q[:, 2])
    assert np.all(ik.status == 0)
    back = kinematics.tcp_position(CRANE, ik.joints[:, 0], ik.joints[:, 1], ik.joints[:, 2])
    np.testing.assert_allclose(back, p, atol=1e-10)


def test_closed_form_ik_agrees_with_newton_ik_on_the_spiral() -> None:
    """The two IK solvers (closed form, Newton with continuation) give the same joints on the spiral."""
    ref = STUDY.reference
    sampled = ref.sample(KIN, STUDY.grid.fine_times())
    assert ref.centre_joints is not None
    newton = tr.inverse_kinematics(KIN, sampled, ref.centre_joints)
    closed = planar_ik(KIN, CRANE, sampled.position[:, :2], sampled.position[:, 2])
    np.testing.assert_allclose(closed.joints, newton.position, atol=1e-9)


@pytest.mark.parametrize(
    ("xy", "xt2", "status"),
    [
        ((8.0, 0.0), 0.5, 1),
        ((0.0, 0.0), 0.5, 1),
        ((1.555, -1.811), 0.0, 2),
        ((-0.206, 0.239), 0.0, 3),
        ((3.0, 0.5), 1.5, 4),
    ],
    ids=["too-far", "too-close", "theta1-range", "theta2-range", "telescope-range"],
)
def test_closed_form_ik_names_why_a_point_is_unreachable(xy: tuple[float, float], xt2: float, status: int) -> None:
    """Out of reach, a joint range exceeded or the telescope out of range each give their own status.

    The joint-range points are the TCP at theta = (-0.5, -1.0) and (0.5, -2.9) rad (xt2 = 0), just
    outside the lift and the tilt range; the other elbow branch is further outside.
    """
    assert int(planar_ik(KIN, CRANE, [xy], [xt2]).status[0]) == status


@settings(max_examples=40, deadline=None)
@given(task=pick_and_place_tasks())
def test_pick_and_place_is_rest_to_rest_clears_the_height_and_is_c2(task: PickAndPlace) -> None:
    """Ends at pick and place, rest during dwells, apex exactly at the clearance, rates = derivatives of the path."""
    pick, place, telescope, move_time, dwell = task.pick, task.place, task.telescope, task.move_time, task.dwell
    t = np.linspace(0.0, task.duration, 4001)
    ref = task.sample(KIN, t)
    np.testing.assert_allclose(ref.position[0], [*pick, telescope[0]], atol=1e-12)
    np.testing.assert_allclose(ref.position[-1], [*place, telescope[1]], atol=1e-12)
    resting = (t <= dwell[0]) | (t >= dwell[0] + move_time)
    np.testing.assert_allclose(ref.velocity[resting], 0.0, atol=1e-12)
    np.testing.assert_allclose(ref.acceleration[resting], 0.0, atol=1e-12)
    # apex: on a dense path grid the highest point is the clearance (from below, to grid resolution)
    y = task.path(np.linspace(0.0, 1.0, 20001))[0][:, 1]
    assert task.clearance - 1e-7 <= y.max() <= task.clearance + 1e-12
    # x moves monotonically from pick to place
    assert np.all(ref.velocity[:, 0] >= -1e-12)
    # C2 across the dwells: central differences of position and velocity give velocity and acceleration
    h = 1e-5
    fine = np.concatenate([t[1:-1:50], [dwell[0], dwell[0] + move_time]])
    up, down = task.sample(KIN, fine + h), task.sample(KIN, fine - h)
    mid = task.sample(KIN, fine)
    scale_v = np.abs(ref.velocity).max() + 1e-12
    scale_a = np.abs(ref.acceleration).max() + 1e-12
    np.testing.assert_allclose((up.position - down.position) / (2 * h), mid.velocity, atol=1e-5 * scale_v)
    np.testing.assert_allclose((up.velocity - down.velocity) / (2 * h), mid.acceleration, atol=1e-5 * scale_a)


def test_septic_law_has_zero_velocity_acceleration_and_jerk_at_both_ends() -> None:
    """s(0) = 0, s(T) = 1, and ds, dds and the jerk (by differences of dds) vanish at both ends."""
    s, ds, dds = septic_law(np.array([0.0, 5.0]), 0.0, 5.0)
    np.testing.assert_array_equal(s, [0.0, 1.0])
    np.testing.assert_array_equal(np.concatenate([ds, dds]), 0.0)
    h = 1e-6  # one-sided differences of dds: O(h) where the jerk vanishes
    jerk = (septic_law(np.array([h, 5.0]), 0.0, 5.0)[2] - septic_law(np.array([0.0, 5.0 - h]), 0.0, 5.0)[2]) / h
    np.testing.assert_allclose(jerk, 0.0, atol=1e-6)


def test_pick_and_place_task_is_reachable_and_starts_the_ik() -> None:
    """The duty mix's pick-and-place is reachable; Newton IK from its closed-form start tracks it."""
    TASK.check_reach(KIN, CRANE)
    ref = TASK.sample(KIN, np.linspace(0.0, TASK.duration, 300))
    joints = tr.inverse_kinematics(KIN, ref, tuple(initial_joints(CRANE, ref)[:2]))
    np.testing.assert_allclose(KIN.position(joints.position)[:, :2], ref.position[:, :2], atol=1e-9)


def test_unreachable_place_names_the_time() -> None:
    """A place point beyond the crane's reach raises naming the first time it leaves the workspace."""
    far = PickAndPlace(pick=(2.0, -1.0), place=(6.5, 0.0), clearance=1.0, telescope=(0.2, 1.0), move_time=8.0)
    with pytest.raises(InvalidInputError, match=r"reference at t = [\d.]+ s .*out of the crane's reach"):
        far.check_reach(KIN, CRANE)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"clearance": -2.0}, "reference.clearance"),
        ({"move_time": 0.0}, "reference.move_time"),
        ({"dwell": [-1.0, 1.0]}, r"reference.dwell\[0\]"),
        ({"telescope": [0.1]}, "reference.telescope: expected a list of 2"),
        ({"kind": "circle"}, "reference.kind"),
        ({"speed": 1.0}, "unknown key"),
    ],
)
def test_bad_pick_and_place_raises_naming_the_field(change: dict, match: str) -> None:
    """Every bad pick-and-place field raises one error naming it."""
    block = {"kind": "pick_and_place", "pick": [1.6, -1.2], "place": [3.6, 0.2], "clearance": 0.8}
    block |= {"telescope": [0.1, 0.8], "move_time": 10.0} | change
    with pytest.raises((InvalidInputError, ConfigError), match=match):
        reference_from_mapping(block, "reference", Path("."), 6.25, NAMES)

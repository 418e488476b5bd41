"""Forward replay: the inverse-dynamics forces, applied open loop, reproduce the joint trajectory."""

from __future__ import annotations

import numpy as np
import pytest

from hiab_sim.crane.description import Crane
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.replay import replay
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import InvalidInputError


def _move(crane: Crane, t: np.ndarray, start: tuple[float, ...], end: tuple[float, ...]) -> JointSamples:
    """Smooth out-and-back motion between fractions ``start`` and ``end`` of each joint's range, period 5 s."""
    low = np.array([crane.lift.joint_range[0], crane.tilt.joint_range[0], crane.telescope.joint_range[0]])
    high = np.array([crane.lift.joint_range[1], crane.tilt.joint_range[1], crane.telescope.joint_range[1]])
    p0, p1 = low + (high - low) * np.array(start), low + (high - low) * np.array(end)
    w = 2.0 * np.pi / 5.0
    tt = t[:, None]
    s, ds, dds = (1 - np.cos(w * tt)) / 2, w * np.sin(w * tt) / 2, w * w * np.cos(w * tt) / 2
    return JointSamples(p0 + (p1 - p0) * s, (p1 - p0) * ds, (p1 - p0) * dds)


def test_replay_tracks_the_trajectory_for_5_s(crane: Crane) -> None:
    """Open-loop forces from the inverse dynamics track theta1, theta2 within 1e-3 rad and xt2 within 1 mm over 5 s.

    The motion sweeps 90 % of the lift and telescope ranges and 40 % of the tilt range, avoiding the corner
    with both booms high where the open-loop crane diverges fastest (see hiab_sim.dynamics.replay).
    """
    t = np.linspace(0.0, 5.0, 501)  # forces on a 10 ms grid, cubic-spline interpolated
    joints = _move(crane, t, (0.05, 0.6, 0.05), (0.95, 0.2, 0.95))
    forces = MujocoInverseDynamics(crane)(joints).force
    result = replay(crane, None, t, joints, forces)
    error = np.abs(result.position - joints.position).max(axis=0)
    assert np.all(error < 1e-3), error
    assert result.loop_residual.max() < 1e-5


def test_replay_holds_a_payload_at_rest(crane: Crane) -> None:
    """Static forces with a 300 kg payload at the TCP keep the crane still for 1 s (within 1e-4)."""
    t = np.linspace(0.0, 1.0, 101)
    position = np.tile([0.8, -1.2, 0.5], (t.size, 1))
    joints = JointSamples.at_rest(position)
    payload = np.array([0.0, -300.0 * crane.gravity, 0.0])
    forces = MujocoInverseDynamics(crane)(joints, tcp_force=payload).force
    result = replay(crane, None, t, joints, forces, tcp_force=payload)
    assert np.abs(result.position - position).max() < 1e-4
    without = replay(crane, None, t, joints, forces)  # the payload's forces without the payload: the crane rises
    assert np.abs(without.position - position).max() > 1e-2


def test_replay_rejects_malformed_forces(crane: Crane) -> None:
    """Forces of the wrong shape, NaN forces or non-increasing times raise InvalidInputError naming the field."""
    t = np.linspace(0.0, 1.0, 11)
    joints = JointSamples.at_rest(np.tile([0.8, -1.2, 0.5], (t.size, 1)))
    with pytest.raises(InvalidInputError, match="forces"):
        replay(crane, None, t, joints, np.zeros((10, 3)))
    with pytest.raises(InvalidInputError, match="forces"):
        replay(crane, None, t, joints, np.full((11, 3), np.nan))
    with pytest.raises(InvalidInputError, match="time"):
        replay(crane, None, t[::-1], joints, np.zeros((11, 3)))

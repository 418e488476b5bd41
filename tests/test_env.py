"""The closed-loop environment: dm_env conformance, the plan's energy in closed loop, payload error."""

from __future__ import annotations

import numpy as np
import pytest
from absl.testing import absltest
from closed_loop_helper import synthetic_plan
from dm_env import test_utils

from hiab_sim.control import CascadeController
from hiab_sim.crane.loader import load_crane
from hiab_sim.env import make_environment
from hiab_sim.env.rollout import run_closed_loop
from hiab_sim.errors import InvalidInputError

CRANE = load_crane("xs031")


class CraneEnvironmentConformance(test_utils.EnvironmentTestMixin, absltest.TestCase):
    """dm_env's own conformance suite on a 0.2 s plan (100 agent steps), run to the end of the episode."""

    def make_object_under_test(self):  # noqa: D102
        return make_environment(synthetic_plan(CRANE, duration=0.2))

    def make_action_sequence(self):  # noqa: D102
        motion = self.environment.task.motion
        for k in range(0, 2 * len(motion.time) + 20, 2):  # past the end: a new episode starts
            yield motion.current[min(k, len(motion.time) - 1)]


def test_a_force_of_the_fine_grid_is_linear_between_its_samples() -> None:
    """A force linear in time comes back exactly between the plan's samples; outside the cycle its ends hold."""
    plan = synthetic_plan(CRANE)
    start, slope = np.array([15.0, -981.0, 2.0]), np.array([40.0, -12.0, 0.5])  # [N], [N/s]
    force = start + np.outer(plan.time, slope)
    times = np.array([-0.2, 0.0, 0.0123, 0.777, plan.time[-1], plan.time[-1] + 0.4])
    expected = start + np.outer(np.clip(times, plan.time[0], plan.time[-1]), slope)
    np.testing.assert_allclose(plan.force_at(force, times), expected, rtol=1e-12, atol=1e-9)
    np.testing.assert_array_equal(plan.force_at(force), force)


@pytest.mark.sim
def test_closed_loop_energy_matches_the_steady_state_model() -> None:
    """Cascade control on the simulated drives draws the steady-state model's energy within 1 % and tracks to 0.5 mm.

    The prediction is the analytic ID with the steady-state EMLA model; the closed loop is MuJoCo
    with the time-domain drives (current loops, friction, inertia as armature): independent paths.
    """
    plan = synthetic_plan(CRANE)
    run, physics = run_closed_loop(plan)
    physics.free()
    assert run.net_energy == pytest.approx(plan.predicted_net_energy, rel=0.01)
    assert run.tcp_error.max() < 5e-4
    assert np.all(run.current_limit_fraction == 0) and np.all(run.voltage_limit_fraction == 0)


@pytest.mark.sim
def test_heavier_end_mass_costs_energy_and_is_still_tracked() -> None:
    """With the end mass 20 % heavier than planned the cycle completes, tracked within 20 mm, at a higher energy."""
    plan = synthetic_plan(CRANE)
    nominal, p0 = run_closed_loop(plan)
    heavy, p1 = run_closed_loop(plan, payload_error=0.2)
    p0.free()
    p1.free()
    assert heavy.time[-1] == pytest.approx(plan.duration)
    assert heavy.tcp_error.max() < 0.02
    assert heavy.net_energy > nominal.net_energy
    assert heavy.tcp_error.max() > nominal.tcp_error.max()


def test_observations_describe_the_drives_and_the_tcp() -> None:
    """Reset starts on the plan with the feedforward currents; the bus power is the drives' sum; reward is -mm."""
    env = make_environment(synthetic_plan(CRANE, duration=0.2))
    step = env.reset()
    obs = step.observation
    motion = env.task.motion
    np.testing.assert_allclose(obs["joint_position"], motion.qpos[0], atol=1e-12)
    np.testing.assert_allclose(obs["current_dq"][:, 1], motion.current[0], atol=1e-12)
    np.testing.assert_allclose(obs["tcp"], motion.planned_tcp[0], atol=1e-9)
    controller = CascadeController(motion, env.physics.drives.drives)
    step = env.step(controller(step))
    obs = step.observation
    assert obs["bus_power"][0] == pytest.approx(obs["electrical_power"].sum())
    assert step.reward == pytest.approx(-1000.0 * np.linalg.norm(obs["tcp"] - obs["reference_tcp"]))
    spec = env.action_spec()
    assert np.all(spec.maximum == env.physics.drives.drives.current_limit)
    env.physics.free()


def test_bad_environment_settings_are_rejected() -> None:
    """A negative payload error or a control step that is no multiple of the physics step name the field."""
    plan = synthetic_plan(CRANE, duration=0.2)
    with pytest.raises(InvalidInputError, match="payload_error"):
        make_environment(plan, payload_error=-0.1)
    with pytest.raises(InvalidInputError, match="control_timestep"):
        make_environment(plan, control_timestep=1.5e-3)

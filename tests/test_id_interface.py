"""The one inverse-dynamics interface: a factory by path name, shared input checks, one length check per build."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics import ID_PATHS, JointSamples, inverse_dynamics, make_inverse_dynamics
from hiab_sim.errors import InvalidInputError
from hiab_sim.model import mjcf

CRANE = load_crane("xs031")
LOW = np.array([CRANE.lift.joint_range[0], CRANE.tilt.joint_range[0], CRANE.telescope.joint_range[0]])
HIGH = np.array([CRANE.lift.joint_range[1], CRANE.tilt.joint_range[1], CRANE.telescope.joint_range[1]])
PAYLOAD = np.array([0.0, -50.0 * 9.81, 0.0])


def _samples(n: int = 25) -> JointSamples:
    rng = np.random.default_rng(11)
    position = LOW + (HIGH - LOW) * rng.uniform(0.05, 0.95, (n, 3))
    return JointSamples(position, rng.normal(0.0, 0.2, (n, 3)), rng.normal(0.0, 0.5, (n, 3)))


def test_both_paths_built_by_name_agree() -> None:
    """The factory's MuJoCo and analytic callables, two independent implementations, give the same forces."""
    joints = _samples()
    mujoco_out = make_inverse_dynamics(CRANE, None, "mujoco")(joints, tcp_force=PAYLOAD)
    analytic_out = make_inverse_dynamics(CRANE, None, "analytic")(joints, tcp_force=PAYLOAD)
    scale = np.max(np.abs(mujoco_out.force))
    np.testing.assert_allclose(analytic_out.force, mujoco_out.force, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(analytic_out.velocity, mujoco_out.velocity, rtol=0, atol=1e-10)


def test_unknown_path_names_the_field() -> None:
    """A path outside ID_PATHS is rejected with the field id_path."""
    assert set(ID_PATHS) == {"mujoco", "analytic"}
    with pytest.raises(InvalidInputError, match="id_path"):
        make_inverse_dynamics(CRANE, None, "magic")


@pytest.mark.parametrize("path", ["mujoco", "analytic"])
def test_bad_inputs_get_the_same_named_error_on_both_paths(path: str) -> None:
    """Both paths reject a joint outside its range and a malformed TCP force with the same field."""
    joints = _samples(4)
    outside = joints.position.copy()
    outside[2, 2] = HIGH[2] + 0.1
    with pytest.raises(InvalidInputError, match="xt2"):
        inverse_dynamics(CRANE, None, JointSamples.at_rest(outside), path=path)
    with pytest.raises(InvalidInputError, match="tcp_force"):
        inverse_dynamics(CRANE, None, joints, path=path, tcp_force=np.ones(2))
    with pytest.raises(InvalidInputError, match="tcp_force"):
        inverse_dynamics(CRANE, None, joints, path=path, tcp_force=np.full(3, np.nan))


def test_a_mujoco_build_checks_the_lengths_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """Building the MuJoCo path for one link-length set runs check_lengths exactly once."""
    calls = []
    original = mjcf.check_lengths

    def counting(crane, lengths):  # type: ignore[no-untyped-def]
        calls.append(lengths)
        return original(crane, lengths)

    # every module that holds the function, wherever it was imported
    for module in list(sys.modules.values()):
        ours = getattr(module, "__name__", "").startswith("hiab_sim")
        if ours and getattr(module, "check_lengths", None) is original:
            monkeypatch.setattr(module, "check_lengths", counting)
    make_inverse_dynamics(CRANE, CRANE.default_lengths, "mujoco")
    assert len(calls) == 1

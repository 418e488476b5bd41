"""The one inverse-dynamics interface: a protocol, and a factory that picks a path by name.

``make_inverse_dynamics(crane, lengths, path)`` builds, for one link-length set Xi, a callable
``id(joints, tcp_force=None) -> ActuatorSamples`` that evaluates the seed's
``[f_x, v_x] = ID(theta, dtheta, ddtheta, robot(Xi))`` (eq. dynamics) by

- ``"mujoco"``: :class:`hiab_sim.dynamics.mujoco_id.MujocoInverseDynamics` (``mj_inverse`` on the
  MJCF model, built once here), or
- ``"analytic"``: :class:`hiab_sim.dynamics.analytic_id.AnalyticInverseDynamics` (closed-chain
  trigonometry and planar Newton-Euler).

The two are independent implementations of the same map and agree to round-off
(``hiab-sim validate``). Lengths are checked once, when the callable is built.
"""

from __future__ import annotations

from typing import Protocol, get_args

from numpy.typing import ArrayLike

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.analytic_id import AnalyticInverseDynamics
from hiab_sim.dynamics.samples import ActuatorSamples, IdPath, JointSamples
from hiab_sim.errors import InvalidInputError

#: The inverse-dynamics paths by name.
ID_PATHS: tuple[str, ...] = get_args(IdPath)


class InverseDynamics(Protocol):
    """Inverse dynamics of one link-length set: joint samples (and a TCP force) in, actuator samples out."""

    def __call__(self, joints: JointSamples, tcp_force: ArrayLike | None = None) -> ActuatorSamples:
        """Actuator samples for joint samples (T, 3); ``tcp_force`` [N] in {W}, (3,) or (T, 3)."""
        ...


def make_inverse_dynamics(crane: Crane, lengths: LinkLengths | None = None, path: str = "mujoco") -> InverseDynamics:
    """Inverse dynamics (seed eq. dynamics) for link lengths Xi (default: the crane's own) by ``path``.

    Raises:
        InvalidInputError: an unknown path (field ``id_path``) or infeasible lengths (the length is named).

    """
    if path == "mujoco":
        # imported here so that the analytic path (and this package) loads without MuJoCo
        from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics

        return MujocoInverseDynamics(crane, lengths)
    if path == "analytic":
        return AnalyticInverseDynamics(crane, lengths)
    raise InvalidInputError("id_path", path, f"must be one of {', '.join(ID_PATHS)}")


def inverse_dynamics(
    crane: Crane,
    lengths: LinkLengths | None,
    joints: JointSamples,
    path: str = "mujoco",
    tcp_force: ArrayLike | None = None,
) -> ActuatorSamples:
    """[f_x, v_x] = ID(theta, dtheta, ddtheta, robot(Xi)) (seed eq. dynamics) by the chosen path, once."""
    return make_inverse_dynamics(crane, lengths, path)(joints, tcp_force=tcp_force)

"""The machine inverse dynamics by path name: one protocol, one factory (no MuJoCo import until asked for).

``make_machine_dynamics(machine, design, path, extras)`` returns a callable
``id(q, dq, ddq, tcp_force=None) -> MachineActuatorSamples`` evaluating the seed's
``[f_x, v_x] = ID(theta, dtheta, ddtheta, robot(Xi))`` (eq. ``dynamics``) for any machine:

- ``"newton_euler"``: :class:`hiab_sim.machine.dynamics.newton_euler.NewtonEulerInverseDynamics`;
- ``"mujoco"``: :class:`hiab_sim.machine.dynamics.mujoco_path.MujocoMachineDynamics`.

Both give the same actuator and pin forces to round-off (``docs/dynamics.md``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.newton_euler import NewtonEulerInverseDynamics
from hiab_sim.machine.dynamics.tree import MachineActuatorSamples, SimulationExtras

#: The inverse-dynamics paths of a machine, by name.
MACHINE_ID_PATHS = ("newton_euler", "mujoco")


class MachineInverseDynamics(Protocol):
    """Inverse dynamics of one machine design: joint samples (and a TCP force) in, actuator samples out."""

    def __call__(self, q: Any, dq: Any, ddq: Any, tcp_force: Any = None) -> MachineActuatorSamples:
        """Actuator and pin forces for joint samples (T, n) and a TCP force (2,) or (T, 2) [N]."""
        ...


def make_machine_dynamics(
    machine: Machine,
    design: Sequence[float] | None = None,
    path: str = "newton_euler",
    extras: SimulationExtras | None = None,
) -> MachineInverseDynamics:
    """Inverse dynamics of ``machine`` at ``design`` (default: the file's) by ``path``.

    Raises:
        InvalidInputError: an unknown path (field ``id_path``), a design outside its bounds.

    """
    if path == "newton_euler":
        return NewtonEulerInverseDynamics(machine, design, extras)
    if path == "mujoco":
        from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics  # MuJoCo only when asked for

        return MujocoMachineDynamics(machine, design, extras)
    raise InvalidInputError("id_path", path, f"must be one of {', '.join(MACHINE_ID_PATHS)}")

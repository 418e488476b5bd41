"""Pin forces by either inverse-dynamics path, picked by name (the analytic path loads without MuJoCo)."""

from __future__ import annotations

from numpy.typing import ArrayLike

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import InvalidInputError
from hiab_sim.structure.pin_loads import PinLoads, analytic_pin_loads


def pin_loads(
    crane: Crane,
    lengths: LinkLengths | None,
    joints: JointSamples,
    path: str = "analytic",
    tcp_force: ArrayLike | None = None,
) -> PinLoads:
    """Pin forces along the motion by the chosen inverse-dynamics path (``analytic`` or ``mujoco``)."""
    lengths = crane.default_lengths if lengths is None else lengths
    if path == "analytic":
        return analytic_pin_loads(crane, lengths, joints, tcp_force)
    if path == "mujoco":
        from hiab_sim.structure.pin_loads_mujoco import MujocoPinLoads

        return MujocoPinLoads(crane, lengths)(joints, tcp_force)
    raise InvalidInputError("id_path", path, "must be one of analytic, mujoco")

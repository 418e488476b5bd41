"""The planner's TCP force applied to the simulation model: ``xfrc_applied`` at site ``tcp`` every physics step.

Where a plan's inverse dynamics took a force F(t) on the TCP [N] (a machine file's payload and soil, a
crane task's payload schedule or inertia), the closed loop applies that same force at the TCP, so that
the ideal plant is the planner's own model: the force at the site and its moment about the centre of
mass of the site's body, at the planned time (the first sample's during the settled start's hold).
"""

from __future__ import annotations

import mujoco
import numpy as np

from hiab_sim.arrays import Array


class TcpLoad:
    """The plan's TCP force F, MuJoCo world (N, 3) [N], applied at site ``tcp`` each physics step (module docstring).

    With a payload mismatch (``payload``: the payload's share P of the force, MuJoCo world (N, 3)
    [N]) the true load is the rest F - P at the site and (1 + e_end) P at the site shifted by
    ``offset`` [m] in the site's frame (:mod:`hiab_sim.env.plant.mismatch`).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        force: Array,
        timestep: float,
        payload: Array | None = None,
        factor: float = 1.0,
        offset: Array | None = None,
    ) -> None:
        self.site = int(model.site("tcp").id)
        self.body = int(model.site_bodyid[self.site])
        self.force = force
        self.timestep = timestep
        self.payload = payload
        self.factor = factor
        self.offset = np.zeros(3) if offset is None else np.asarray(offset, dtype=float)

    def apply(self, model: mujoco.MjModel, data: mujoco.MjData, holding: bool) -> None:
        """Set ``xfrc_applied`` of the TCP's body to F at the site (force and moment about the com)."""
        k = 0 if holding else int(min(max(round(data.time / self.timestep), 0), len(self.force) - 1))
        force = self.force[k]
        arm = data.site_xpos[self.site] - data.xipos[self.body]
        if self.payload is None:
            data.xfrc_applied[self.body, :3] = force
            data.xfrc_applied[self.body, 3:] = np.cross(arm, force)
            return
        rest = force - self.payload[k]
        true = self.factor * self.payload[k]
        lever = arm + data.site_xmat[self.site].reshape(3, 3) @ self.offset
        data.xfrc_applied[self.body, :3] = rest + true
        data.xfrc_applied[self.body, 3:] = np.cross(arm, rest) + np.cross(lever, true)

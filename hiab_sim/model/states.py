"""MuJoCo quantities of given states of a compiled model: site positions and mechanical energy.

Both models of the package, the crane's (:mod:`hiab_sim.model.mjcf`) and a machine file's
(:mod:`hiab_sim.machine.dynamics.mjcf_build`), read these the same way, one state at a time:

* site positions from the forward kinematics (``mj_kinematics``), world frame [m];
* the potential energy of gravity (``mj_energyPos``, zero at the world origin) and the kinetic
  energy 1/2 qvel^T M qvel (``mj_energyVel``, after ``mj_fwdPosition`` has built M) [J].
"""

from __future__ import annotations

import mujoco
import numpy as np

from hiab_sim.arrays import Array


def site_positions(model: mujoco.MjModel, qpos: Array, site: str) -> Array:
    """World position (N, 3) [m] of site ``site`` at each row of ``qpos`` (N, nq)."""
    data = mujoco.MjData(model)
    index = model.site(site).id
    out = np.empty((len(qpos), 3))
    for k, row in enumerate(qpos):
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        out[k] = data.site_xpos[index]
    return out


def mechanical_energies(model: mujoco.MjModel, data: mujoco.MjData, qpos: Array, qvel: Array) -> tuple[Array, Array]:
    """Potential and kinetic energy [J], (N,) each, of the states (``qpos``, ``qvel``) rows; ``data`` is scratch."""
    out = np.empty((len(qpos), 2))
    for i in range(len(qpos)):
        data.qpos[:] = qpos[i]
        data.qvel[:] = qvel[i]
        mujoco.mj_fwdPosition(model, data)
        mujoco.mj_energyPos(model, data)
        mujoco.mj_energyVel(model, data)
        out[i] = data.energy
    return out[:, 0], out[:, 1]

"""The mass matrix of the independent joints from MuJoCo: ``mj_fullM`` projected through the loop Jacobian.

At a loop-consistent state (:meth:`hiab_sim.dynamics.mujoco_id.MujocoInverseDynamics.state`) the
loops' in-plane rows J (of ``efc_J``) constrain qvel: J qvel = 0. Splitting the dofs into the
independent joints i (:data:`hiab_sim.crane.names.JOINT_NAMES`) and the rest d,
qvel = Z dq_i with Z_i = I and Z_d = -J_d^-1 J_i, so the kinetic energy is dq_i^T (Z^T M Z) dq_i / 2
and the actuator Jacobian is J_x = Z_a (the rows of the actuated slides).
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.names import JOINT_NAMES
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples


def loop_projection(model: mujoco.MjModel, data: mujoco.MjData, chains: list[str]) -> Array:
    """Z (nv, n_independent) at the state in ``data`` (after ``mj_fwdPosition``): qvel = Z dq_i."""
    axis = data.xaxis[model.joint(JOINT_NAMES[0]).id]
    in_plane = np.flatnonzero(np.abs(axis) < 0.5)
    rows = np.concatenate([3 * model.equality(f"{c}_loop").id + in_plane for c in chains])
    J = data.efc_J.reshape(-1, model.nv)[rows]
    independent = np.array([int(model.joint(name).dofadr[0]) for name in JOINT_NAMES])
    dependent = np.array([v for v in range(model.nv) if v not in set(independent)])
    Z = np.zeros((model.nv, independent.size))
    Z[independent] = np.eye(independent.size)
    Z[dependent] = -np.linalg.solve(J[:, dependent], J[:, independent])
    return Z


def mujoco_mass_matrix(crane: Crane, lengths: LinkLengths | None, position: ArrayLike) -> tuple[Array, Array]:
    """Z^T M Z (T, n, n) and J_x (T, n_a, n) at static poses (T, n), from MuJoCo."""
    inverse = MujocoInverseDynamics(crane, lengths)
    m, d = inverse.model, mujoco.MjData(inverse.model)
    qpos, _, _ = inverse.state(JointSamples.at_rest(np.atleast_2d(np.asarray(position, dtype=float))))
    actuated = [int(m.jnt_dofadr[m.actuator_trnid[a, 0]]) for a in range(m.nu)]
    chains = [c.name for c in crane.chains]
    T, n = qpos.shape[0], len(JOINT_NAMES)
    M = np.zeros((T, n, n))
    Jx = np.zeros((T, m.nu, n))
    full = np.zeros((m.nv, m.nv))
    for t in range(T):
        d.qpos[:] = qpos[t]
        d.qvel[:] = 0.0
        mujoco.mj_fwdPosition(m, d)
        mujoco.mj_fullM(m, d, full)
        Z = loop_projection(m, d, chains)
        M[t] = Z.T @ full @ Z
        Jx[t] = Z[actuated]
    return 0.5 * (M + np.swapaxes(M, 1, 2)), Jx

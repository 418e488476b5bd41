"""Loop-consistent poses of an MJCF mechanism: the pin residuals of its ``connect`` equalities and Newton's method.

The unknowns are the joints of the chains' own bodies (actuator cylinders and rods, rockers,
couplers): with the machine's joints and the locked joints held, the in-plane pin residuals
(2 per ``connect``, along the plane's two axes) are a square system in them. Positions in m,
angles in rad, MuJoCo's world frame.
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from hiab_sim.machine.mjcf_import.graph import Mechanism, connect_points

Array = NDArray[np.float64]

#: Newton iterations and in-plane residual tolerance [m].
NEWTON_STEPS = 30
NEWTON_TOL = 1e-13


def plane_axes(mech: Mechanism) -> Array:
    """(3, 3) columns: the machine's x, y (up) and z (plane normal) axes in MuJoCo's world."""
    up = -mech.down
    x = np.cross(up, mech.normal)
    return np.column_stack([x / np.linalg.norm(x), up, mech.normal])


def pins(mech: Mechanism) -> list[int]:
    """Equality ids of the connects, in edge order."""
    return [e.index for e in mech.edges if e.kind == "pin"]


def residual_and_jacobian(mech: Mechanism, data: mujoco.MjData) -> tuple[Array, Array]:
    """In-plane pin residuals (2 n_pins,) and their Jacobian (2 n_pins, nv) at the data's kinematics."""
    model = mech.model
    axes = plane_axes(mech)[:, :2].T
    eqs = pins(mech)
    residual = np.empty(2 * len(eqs))
    jac = np.empty((2 * len(eqs), model.nv))
    ja, jb = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for k, e in enumerate(eqs):
        p1, p2 = connect_points(model, data, e)
        b1, b2 = _bodies(model, e)
        mujoco.mj_jac(model, data, ja, None, p1, b1)
        mujoco.mj_jac(model, data, jb, None, p2, b2)
        residual[2 * k : 2 * k + 2] = axes @ (p1 - p2)
        jac[2 * k : 2 * k + 2] = axes @ (ja - jb)
    return residual, jac


def jac_dot_qvel(mech: Mechanism, data: mujoco.MjData) -> Array:
    """d/dt of the pin Jacobian times qvel (2 n_pins,) at the data's kinematics and velocities."""
    model = mech.model
    axes = plane_axes(mech)[:, :2].T
    eqs = pins(mech)
    out = np.empty(2 * len(eqs))
    ja, jb = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for k, e in enumerate(eqs):
        p1, p2 = connect_points(model, data, e)
        b1, b2 = _bodies(model, e)
        mujoco.mj_jacDot(model, data, ja, None, p1, b1)
        mujoco.mj_jacDot(model, data, jb, None, p2, b2)
        out[2 * k : 2 * k + 2] = axes @ ((ja - jb) @ data.qvel)
    return out


def _bodies(model: mujoco.MjModel, e: int) -> tuple[int, int]:
    a, b = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
    if model.eq_objtype[e] == mujoco.mjtObj.mjOBJ_SITE:
        return int(model.site_bodyid[a]), int(model.site_bodyid[b])
    return a, b


def close(mech: Mechanism, data: mujoco.MjData, dependent: list[int]) -> float:
    """Newton on the dependent dofs (hinges and slides: qpos = qvel) from the data's qpos; the final |residual| [m]."""
    model = mech.model
    dofs = np.array(dependent, dtype=int)
    qadr = model.jnt_qposadr[model.dof_jntid[dofs]] if len(dofs) else dofs
    norm = np.inf
    for _ in range(NEWTON_STEPS):
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        residual, jac = residual_and_jacobian(mech, data)
        norm = float(np.max(np.abs(residual))) if residual.size else 0.0
        if norm < NEWTON_TOL:
            break
        step = np.linalg.lstsq(jac[:, dofs], -residual, rcond=None)[0]
        data.qpos[qadr] += step
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    return norm

"""Loop-consistent poses of an MJCF mechanism: the pin residuals of its ``connect`` equalities and Newton's method.

The unknowns are the joints of the chains' own bodies (actuator cylinders and rods, rockers,
couplers): with the machine's joints and the locked joints held, the in-plane pin residuals
(2 per ``connect``, along the plane's two axes) are a square system in them. Positions in m,
angles in rad, MuJoCo's world frame.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.machine.mjcf_import.graph import Mechanism, connect_points

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
    eqs = pins(mech)
    residual = np.empty(2 * len(eqs))
    jac = np.empty((2 * len(eqs), mech.model.nv))
    for k, axes, gap, djac in _pin_terms(mech, data, eqs, mujoco.mj_jac):
        residual[2 * k : 2 * k + 2] = axes @ gap
        jac[2 * k : 2 * k + 2] = axes @ djac
    return residual, jac


def jac_dot_qvel(mech: Mechanism, data: mujoco.MjData) -> Array:
    """d/dt of the pin Jacobian times qvel (2 n_pins,) at the data's kinematics and velocities."""
    eqs = pins(mech)
    out = np.empty(2 * len(eqs))
    for k, axes, _, djac in _pin_terms(mech, data, eqs, mujoco.mj_jacDot):
        out[2 * k : 2 * k + 2] = axes @ (djac @ data.qvel)
    return out


def _pin_terms(
    mech: Mechanism, data: mujoco.MjData, eqs: list[int], jac_fn: Callable[..., None]
) -> Iterator[tuple[int, Array, Array, Array]]:
    """Per pin k: the plane's axes (2, 3), the points' gap p1 - p2 [m] (3,) and ``jac_fn``'s J1 - J2 (3, nv)."""
    model = mech.model
    axes = plane_axes(mech)[:, :2].T
    ja, jb = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for k, e in enumerate(eqs):
        p1, p2 = connect_points(model, data, e)
        b1, b2 = _bodies(model, e)
        jac_fn(model, data, ja, None, p1, b1)
        jac_fn(model, data, jb, None, p2, b2)
        yield k, axes, p1 - p2, ja - jb


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

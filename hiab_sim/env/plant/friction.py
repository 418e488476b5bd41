"""Coulomb and viscous friction in the hinges and the actuators' pins of any MJCF mechanism with loop pins.

Every closed loop of the model is a site-based ``connect`` equality (the crane MJCF's rod-end pins,
:mod:`hiab_sim.model.mjcf`; a machine file's loop pins, :mod:`hiab_sim.machine.dynamics.mjcf_build`):
site 1 on body a, site 2 on body b. Friction sits on every rotation of the loop it closes:

* every hinge joint on the tree path between body a and body b: a joint named in ``hinges`` (the
  machine's own joints: the crane's boom hinges, a machine file's link joints) gets the hinge
  friction (``frictionloss`` T_c [N m], ``damping`` c [N m s/rad]); any other hinge on the path (an
  actuator's base pin, a linkage's rocker and coupler pins) gets the pin friction;
* the loop pin itself: its rotation rate is body b's angular rate minus body a's. All hinge axes
  of a planar mechanism are parallel to one normal n, so that rate is the fixed tendon
  ``<equality>_rod_pin`` = sum_j s_j qdot_j over the path's hinges, s_j = +-1 (n . axis_j) on b's
  side, -+1 on a's side (n: the first hinge's axis on b's side); slides do not turn.

On the crane each chain's path is the boom hinge (b) and the barrel's base pin (a): q_boom - q_barrel.

MuJoCo treats ``frictionloss`` as a constraint (static friction included, no regularisation) and
the damping implicitly, so the model stays stable at the physics step. The power they dissipate is
:func:`friction_power`: sum over friction rows of f_i (J qvel)_i, minus sum c_j qdot_j^2 over the
damped joints and tendons (<= 0), with the rates after the step: the ``implicitfast`` step applies
damping and constraint forces at the new rate v', so h f v' is the work they do over the step (the
rate at the step's start would miscount a light body's step-to-step reversals).
"""

from __future__ import annotations

from collections.abc import Collection

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.env.plant.config import JointFriction
from hiab_sim.errors import ConfigError

#: |n . axis| below 1 by more than this: the mechanism is not planar (its hinges are not parallel).
PARALLEL_TOLERANCE = 1e-9


def _ancestors(model: mujoco.MjModel, body: int) -> list[int]:
    """The body and its ancestors up to the world body (0), child first."""
    out = [body]
    while out[-1] != 0:
        out.append(int(model.body_parentid[out[-1]]))
    return out


def _hinges_below(model: mujoco.MjModel, data: mujoco.MjData, body: int, top: int) -> list[tuple[str, Array]]:
    """(hinge name, world axis) of every body from ``body`` up to, not including, ``top``, child first."""
    out = []
    for node in _ancestors(model, body):
        if node == top:
            break
        for j in range(model.body_jntadr[node], model.body_jntadr[node] + model.body_jntnum[node]):
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
                out.append((model.joint(j).name, data.xaxis[j].copy()))
    return out


def loop_path(model: mujoco.MjModel, data: mujoco.MjData, site_a: str, site_b: str) -> list[tuple[str, float]]:
    """(hinge, s_j) on the tree path between the bodies of two sites, b's side first (module docstring).

    ``data`` holds the kinematics of ``model`` (``mj_kinematics``) for the hinges' world axes.

    Raises:
        ConfigError: no hinge on the path, or a hinge not parallel to the others (not planar).

    """
    body_a, body_b = int(model.site(site_a).bodyid[0]), int(model.site(site_b).bodyid[0])
    above_a = set(_ancestors(model, body_a))
    common = next(node for node in _ancestors(model, body_b) if node in above_a)
    side_b = _hinges_below(model, data, body_b, common)
    side_a = _hinges_below(model, data, body_a, common)
    if not side_b and not side_a:
        raise ConfigError(f"pin {site_a} - {site_b}: no hinge between its two bodies for the pin's rotation")
    normal = (side_b or side_a)[0][1]
    path = []
    for sign, side in ((1.0, side_b), (-1.0, side_a)):
        for name, axis in side:
            alignment = float(normal @ axis)
            if abs(abs(alignment) - 1.0) > PARALLEL_TOLERANCE:
                raise ConfigError(f"pin {site_a} - {site_b}: hinge '{name}' is not parallel to the loop's other hinges")
            path.append((name, sign * float(np.sign(alignment))))
    return path


def add_joint_friction(
    spec: mujoco.MjSpec, friction: JointFriction, hinges: Collection[str]
) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Add the friction of every loop pin's path to ``spec``; ``hinges`` the machine's own joints (module docstring).

    Returns:
        The names of the joints with friction and of the loop-pin tendons.

    """
    joints: list[str] = []
    tendons: list[str] = []
    pins = [e for e in spec.equalities if e.type == mujoco.mjtEq.mjEQ_CONNECT and e.objtype == mujoco.mjtObj.mjOBJ_SITE]
    if not pins:
        return (), ()
    model = spec.compile()  # the topology and the hinges' world axes of the mechanism as built
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    for equality in pins:
        path = loop_path(model, data, equality.name1, equality.name2)
        for name, _ in path:
            if name in joints:
                continue
            joint = spec.joint(name)
            main = name in hinges
            joint.frictionloss = friction.hinge_coulomb_N_m if main else friction.pin_coulomb_N_m
            viscous = friction.hinge_viscous_N_m_s_per_rad if main else friction.pin_viscous_N_m_s_per_rad
            joint.damping = [viscous, 0.0, 0.0]
            joints.append(name)
        tendon = spec.add_tendon(name=f"{equality.name}_rod_pin")
        for name, coefficient in path:
            tendon.wrap_joint(name, coefficient)
        tendon.frictionloss = friction.pin_coulomb_N_m
        tendon.damping = [friction.pin_viscous_N_m_s_per_rad, 0.0, 0.0]
        tendons.append(tendon.name)
    return tuple(joints), tuple(tendons)


class FrictionMeter:
    """Power dissipated by the joint and tendon friction of a compiled model (module docstring)."""

    def __init__(self, model: mujoco.MjModel, joints: tuple[str, ...] = (), tendons: tuple[str, ...] = ()) -> None:
        self.dofs = np.array([model.jnt_dofadr[model.joint(name).id] for name in joints], dtype=int)
        self.joint_damping = np.array([model.dof_damping[d] for d in self.dofs])
        ids = [model.tendon(name).id for name in tendons]
        self.tendon_damping = np.array([model.tendon_damping[t] for t in ids])
        # Fixed tendons: rate = sum coef_j qdot_j over their joints' dofs (wrap_objid names the joint).
        self.tendon_rows = np.zeros((len(ids), model.nv))
        for row, t in enumerate(ids):
            for w in range(model.tendon_adr[t], model.tendon_adr[t] + model.tendon_num[t]):
                self.tendon_rows[row, model.jnt_dofadr[model.wrap_objid[w]]] = model.wrap_prm[w]
        self._velocity = np.zeros(0)  # J qvel over the constraint rows, reused while nefc stays

    def power(self, model: mujoco.MjModel, data: mujoco.MjData) -> float:
        """Dissipated power [W] (>= 0) at the state in ``data``, with its last solver's friction forces.

        MuJoCo orders the constraint rows equality, friction (dof, then tendon), limits, contacts, so
        the friction rows are ``ne .. ne + nf - 1``; J v is formed in a buffer kept between steps.
        """
        coulomb = 0.0
        nf = data.nf
        if nf:
            nefc = data.nefc
            if self._velocity.size != nefc:
                self._velocity = np.zeros(nefc)
            velocity = self._velocity
            mujoco.mj_mulJacVec(model, data, velocity, data.qvel)
            rows = slice(data.ne, data.ne + nf)
            coulomb = float(-(data.efc_force[rows] @ velocity[rows]))
        qvel = data.qvel
        viscous = float(self.joint_damping @ qvel[self.dofs] ** 2)
        if self.tendon_damping.size:
            viscous += float(self.tendon_damping @ (self.tendon_rows @ qvel) ** 2)
        return coulomb + viscous

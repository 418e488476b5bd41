"""Coulomb and viscous friction in the boom hinges and the actuators' pins, added to the MuJoCo model.

Every closed chain's ``connect`` equality names the rod-end site (on the rod, whose parent body is
the actuator's barrel, hinged at its base pin) and the boom pivot site (on the boom, hinged at the
boom hinge). Friction is placed on the three rotations of the chain:

* boom hinge: joint friction on the boom's hinge (``frictionloss`` T_c [N m], ``damping`` c [N m s/rad]);
* base pin: the same on the barrel's hinge;
* rod-end pin: its rotation rate is the boom's minus the barrel's angular rate (both hinge on the same
  parent about parallel axes), a fixed tendon ``<equality>_rod_pin`` = q_boom - q_barrel carries it.

MuJoCo treats ``frictionloss`` as a constraint (static friction included, no regularisation) and
the damping implicitly, so the model stays stable at the physics step. The power they dissipate is
:func:`friction_power`: sum over friction rows of f_i (J qvel)_i, minus sum c_j qdot_j^2 over the
damped joints and tendons (<= 0), with the rates after the step: the ``implicitfast`` step applies
damping and constraint forces at the new rate v', so h f v' is the work they do over the step (the
rate at the step's start would miscount a light body's step-to-step reversals).
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from hiab_sim.env.plant.config import JointFriction
from hiab_sim.errors import ConfigError

Array = NDArray[np.float64]


def _hinge_of(body: mujoco.MjsBody, what: str) -> mujoco.MjsJoint:
    hinges = [j for j in body.joints if j.type == mujoco.mjtJoint.mjJNT_HINGE]
    if len(hinges) != 1:
        raise ConfigError(f"{what} body '{body.name}' must have exactly one hinge joint, has {len(hinges)}")
    return hinges[0]


def add_joint_friction(spec: mujoco.MjSpec, friction: JointFriction) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Add the friction of every closed chain to ``spec`` (module docstring).

    Returns:
        The names of the joints with friction and of the rod-pin tendons.

    """
    joints: list[str] = []
    tendons: list[str] = []
    for equality in spec.equalities:
        if equality.type != mujoco.mjtEq.mjEQ_CONNECT or equality.objtype != mujoco.mjtObj.mjOBJ_SITE:
            continue
        rod = spec.site(equality.name1).parent
        boom = spec.site(equality.name2).parent
        barrel = rod.parent
        pin = _hinge_of(barrel, "barrel")
        hinge = _hinge_of(boom, "boom")
        if barrel.parent.name != boom.parent.name:
            raise ConfigError(f"{equality.name}: barrel and boom must hinge on the same body for the rod-pin friction")
        hinge.frictionloss = friction.hinge_coulomb_N_m
        hinge.damping = [friction.hinge_viscous_N_m_s_per_rad, 0.0, 0.0]
        pin.frictionloss = friction.pin_coulomb_N_m
        pin.damping = [friction.pin_viscous_N_m_s_per_rad, 0.0, 0.0]
        tendon = spec.add_tendon(name=f"{equality.name}_rod_pin")
        tendon.wrap_joint(hinge.name, 1.0)
        tendon.wrap_joint(pin.name, -1.0)
        tendon.frictionloss = friction.pin_coulomb_N_m
        tendon.damping = [friction.pin_viscous_N_m_s_per_rad, 0.0, 0.0]
        tendons.append(tendon.name)
        joints += [hinge.name, pin.name]
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

    def power(self, model: mujoco.MjModel, data: mujoco.MjData) -> float:
        """Dissipated power [W] (>= 0) at the state in ``data``, with its last solver's friction forces."""
        friction = (data.efc_type == mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF) | (
            data.efc_type == mujoco.mjtConstraint.mjCNSTR_FRICTION_TENDON
        )
        coulomb = 0.0
        if friction.any():
            velocity = np.zeros(data.nefc)
            mujoco.mj_mulJacVec(model, data, velocity, data.qvel)
            coulomb = float(-(data.efc_force[friction] @ velocity[friction]))
        viscous = float(self.joint_damping @ data.qvel[self.dofs] ** 2)
        if self.tendon_damping.size:
            viscous += float(self.tendon_damping @ (self.tendon_rows @ data.qvel) ** 2)
        return coulomb + viscous

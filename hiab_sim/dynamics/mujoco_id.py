"""Actuator forces and velocities from MuJoCo inverse dynamics on the MJCF model (seed eq. dynamics, const_a).

``MujocoInverseDynamics(crane, lengths)(joints)`` maps samples of the independent joints
(Θ1, Θ2, xt2 with rates and accelerations) to the actuator forces f_x [N] and velocities
v_x [m/s] of lift, tilt and telescope, [f_x, v_x] = ID(θ, dθ, ddθ, robot(Xi)) (eq. dynamics).
The model (:mod:`hiab_sim.model.mjcf`) is built once per object, i.e. per link-length set.

Two passes over the samples, each one MuJoCo pipeline call per sample, with everything else
vectorised over samples:

1. **Loop-consistent state from MuJoCo's own kinematics.** The boom pivot S (site
   ``<chain>_boom_pivot``) and the cylinder base pivot P (site ``<chain>_base_pivot``, on the
   hinge axis of the cylinder) ride on the serial chain base -> lift boom -> tilt boom, so their
   motion does not depend on the passive joints. One ``mj_inverse`` call per sample with the
   independent joints set (passive joints at 0) evaluates frame sensors: positions, linear
   velocities and linear accelerations of S and P, the cylinder's zero-angle axis e0, and the
   parent's angular velocity and acceleration. The loop closes when the rod end lies on S, i.e.
   the passive coordinates are the polar coordinates of d = S - P seen from P (n: the common
   hinge axis in the world, s = |d|, x0 = Lc + Lc0):

       x   = s - x0,                    c   = atan2(n.(e0 x d), e0.d)          (cylinder hinge q1)
       dx  = d.dd / s,                  dc  = n.(d x dd)/s^2 - n.w_parent
       ddx = (dd.dd + d.ddd)/s - dx^2/s,
       ddc = n.(d x ddd)/s^2 - 2 dx n.(d x dd)/s^3 - n.a_parent

   This is exact (no iteration) and uses no formula of :mod:`hiab_sim.crane.mechanism`: the
   triangle trigonometry (eqs. qus .. DDthetas) stays an independent path for validation.

2. **Inverse dynamics and projection.** With the full state (q, qvel, qacc) loop-consistent,
   ``mj_inverse`` gives qfrc_inverse = M qacc + c(q, qvel) - qfrc_passive - qfrc_constraint.
   The loops are soft ``connect`` equalities: on a loop-consistent state their residual and
   its rate are ~0, so the inverse constraint force is ~0 too and qfrc_inverse at a cylinder
   slide is *not* the cylinder force (it is the force that would move the slide if the loop
   were open: 99.5 N instead of 67,920 N on a one-loop test crane). The crane's real balance is

       tau = M qacc + c - tau_ext = S^T f + J^T lambda,

   where S selects the actuated slides (x1, x2, xt2), J (4 x nv) is the loop-closure Jacobian
   (in-plane rows of the ``connect`` equalities' ``efc_J``) and lambda the pin forces; every
   unactuated joint (Θ1, Θ2, both cylinder hinges) is unloaded. Split the dofs into the
   actuated a = (x1, x2, xt2) and the dependent d = (Θ1, Θ2, q1_lift, q1_tilt). The rows of
   d give tau_d = J_d^T lambda, so lambda = J_d^-T tau_d (J_d is regular away from a flat
   triangle, const_k), and the rows of a give

       f = tau_a - J_a^T J_d^-T tau_d = Z^T tau,    Z = [I; -J_d^-1 J_a] (qvel = Z v_x).

   Z spans the loop's admissible velocities parameterised by the actuator velocities, so this
   is the principle of virtual power: f . v_x = tau . qvel for every admissible motion. Any
   constraint force MuJoCo adds lies in the range of J^T and drops out (Z^T J^T = 0), so the
   soft-constraint model does not enter the result. The external TCP force enters as
   tau_ext = J_tcp^T F (``mj_jacSite`` on site ``tcp``; mj_inverse does not subtract applied
   forces itself).

Joint samples and the TCP force are validated before MuJoCo sees them, by the checks both paths
share (:mod:`hiab_sim.dynamics.checks`); the lengths once, when :func:`hiab_sim.model.mjcf.build_spec`
builds the model.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import CHAIN_NAMES, Crane, LinkLengths
from hiab_sim.crane.names import JOINT_NAMES
from hiab_sim.dynamics.checks import check_joints, tcp_force_samples
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples
from hiab_sim.model.mjcf import SLIDES, build_spec, source_to_world
from hiab_sim.model.states import mechanical_energies

#: Per chain, the frame sensors of pass 1, in this order (3 values each).
_SENSORS = (
    ("boom_pivot", mujoco.mjtSensor.mjSENS_FRAMEPOS),
    ("boom_pivot", mujoco.mjtSensor.mjSENS_FRAMELINVEL),
    ("boom_pivot", mujoco.mjtSensor.mjSENS_FRAMELINACC),
    ("base_pivot", mujoco.mjtSensor.mjSENS_FRAMEPOS),
    ("base_pivot", mujoco.mjtSensor.mjSENS_FRAMELINVEL),
    ("base_pivot", mujoco.mjtSensor.mjSENS_FRAMELINACC),
    ("base_pivot", mujoco.mjtSensor.mjSENS_FRAMEXAXIS),
    ("base_pivot", mujoco.mjtSensor.mjSENS_FRAMEANGVEL),
    ("base_pivot", mujoco.mjtSensor.mjSENS_FRAMEANGACC),
)
_CHAINS = CHAIN_NAMES
_DEPENDENT = (*JOINT_NAMES[:2], *(f"{c}_q1" for c in CHAIN_NAMES))


def _dot(a: Array, b: Array) -> Array:
    return np.einsum("...i,...i->...", a, b)


class MujocoInverseDynamics:
    """Inverse dynamics of the crane for one link-length set (seed eq. dynamics), reusable.

    Build once per link-length set, call many times: the MuJoCo model, data and the index
    arrays are created here; a call allocates only its (T, .) work arrays.

    Args:
        crane: the crane description.
        lengths: link lengths Xi (default: the crane's own).

    Raises:
        InvalidInputError: infeasible lengths (const_g .. const_k), the field is named.

    """

    def __init__(self, crane: Crane, lengths: LinkLengths | None = None) -> None:
        self.crane = crane
        self.lengths = crane.default_lengths if lengths is None else lengths
        spec = build_spec(crane, self.lengths)
        spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
        for chain in _CHAINS:
            for site, kind in _SENSORS:
                spec.add_sensor(type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname=f"{chain}_{site}")
        #: Pass 2 model: equality rows present (for efc_J), no sensors evaluated (mj_inverseSkip).
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        #: Pass 1 model: the same model without constraints; its sensors give the serial-chain motion.
        self._kin_model = copy.copy(self.model)
        self._kin_model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
        self._kin_data = mujoco.MjData(self._kin_model)

        m = self.model
        adr = {m.joint(j).name: int(m.joint(j).dofadr[0]) for j in range(m.njnt)}
        if m.nq != m.nv:
            raise AssertionError("the crane model has only hinges and slides")
        self._independent = np.array([adr[n] for n in JOINT_NAMES])
        self._slides = np.array([adr[n] for n in SLIDES])
        self._dependent = np.array([adr[n] for n in _DEPENDENT])
        self._cylinder = np.array([adr[f"{c}_q1"] for c in _CHAINS])
        self._stroke = np.array([adr[n] for n in SLIDES[:2]])
        self._x0 = np.array([getattr(self.lengths, c).x0 for c in _CHAINS])
        self._tcp = m.site("tcp").id
        mujoco.mj_kinematics(m, self.data)
        axes = self.data.xaxis[[m.joint(n).id for n in _DEPENDENT]]  # the booms' and cylinders' hinges
        self._axis = axes[0].copy()  # common hinge axis n in the world
        if np.max(np.abs(axes - self._axis)) > 1e-12:
            raise AssertionError("hinge axes of a planar crane must be parallel")
        # In-plane rows of the two connect equalities in efc_J (the third row is along n).
        in_plane = np.flatnonzero(np.abs(self._axis) < 0.5)
        self._loop_rows = np.concatenate([in_plane, 3 + in_plane])

    # -----------------------------------------------------------------------------------------

    def state(self, joints: JointSamples) -> tuple[Array, Array, Array]:
        """Loop-consistent full state (qpos, qvel, qacc), each (T, nv), from MuJoCo's kinematics (pass 1).

        Raises:
            InvalidInputError: a joint sample outside its range, or not finite.

        """
        check_joints(self.crane, self.lengths, joints)
        m, d = self._kin_model, self._kin_data
        T = len(joints)
        qpos = np.zeros((T, m.nv))
        qvel = np.zeros((T, m.nv))
        qacc = np.zeros((T, m.nv))
        qpos[:, self._independent] = joints.position
        qvel[:, self._independent] = joints.velocity
        qacc[:, self._independent] = joints.acceleration
        sensed = np.empty((T, m.nsensordata))
        d_qpos, d_qvel, d_qacc, d_sensor = d.qpos, d.qvel, d.qacc, d.sensordata
        inverse = mujoco.mj_inverse
        for i in range(T):
            d_qpos[:] = qpos[i]
            d_qvel[:] = qvel[i]
            d_qacc[:] = qacc[i]
            inverse(m, d)
            sensed[i] = d_sensor
        # (T, chain, sensor, xyz): S, dS, ddS, P, dP, ddP, e0, w_parent, a_parent
        s = sensed.reshape(T, 2, len(_SENSORS), 3)
        n = self._axis
        dist = s[:, :, 0] - s[:, :, 3]
        rate = s[:, :, 1] - s[:, :, 4]
        accel = s[:, :, 2] - s[:, :, 5]  # the accelerometer's -g offset cancels
        e0 = s[:, :, 6]
        length = np.sqrt(_dot(dist, dist))
        dlength = _dot(dist, rate) / length
        ddlength = (_dot(rate, rate) + _dot(dist, accel)) / length - dlength**2 / length
        turn = _dot(np.cross(dist, rate), n) / length**2
        angle = np.arctan2(_dot(np.cross(e0, dist), n), _dot(e0, dist))
        dturn = _dot(np.cross(dist, accel), n) / length**2 - 2.0 * dlength * turn / length
        qpos[:, self._stroke] = length - self._x0
        qvel[:, self._stroke] = dlength
        qacc[:, self._stroke] = ddlength
        qpos[:, self._cylinder] = angle
        qvel[:, self._cylinder] = turn - s[:, :, 7] @ n
        qacc[:, self._cylinder] = dturn - s[:, :, 8] @ n
        return qpos, qvel, qacc

    def __call__(self, joints: JointSamples, tcp_force: ArrayLike | None = None) -> ActuatorSamples:
        """Actuator samples [f_x, v_x] = ID(θ, dθ, ddθ, robot(Xi)) (eq. dynamics), order lift, tilt, telescope.

        Args:
            joints: samples of (Θ1 [rad], Θ2 [rad], xt2 [m]) with rates and accelerations, (T, 3).
            tcp_force: force of the environment on the TCP in the source world frame {W} [N],
                (3,) or (T, 3); e.g. a payload of mass m is (0, -m g, 0).

        Returns:
            Forces f_x [N] (> 0 extends), velocities v_x = dx/dt [m/s], accelerations [m/s^2]
            and strokes x [m], each (T, 3).

        Raises:
            InvalidInputError: a joint sample out of range or not finite, a malformed tcp_force.

        """
        T = len(joints)
        force_samples = tcp_force_samples(tcp_force, T)
        external = None if force_samples is None else source_to_world(force_samples)
        qpos, qvel, qacc = self.state(joints)
        m, d = self.model, self.data
        nv = m.nv
        tau = np.empty((T, nv))
        efc = np.empty((T, 6 * nv))
        jac = np.empty((T, 3, nv)) if external is not None else None
        d_qpos, d_qvel, d_qacc, d_tau = d.qpos, d.qvel, d.qacc, d.qfrc_inverse
        inverse, stage = mujoco.mj_inverseSkip, int(mujoco.mjtStage.mjSTAGE_NONE)
        for i in range(T):
            d_qpos[:] = qpos[i]
            d_qvel[:] = qvel[i]
            d_qacc[:] = qacc[i]
            inverse(m, d, stage, 1)
            tau[i] = d_tau
            efc[i] = d.efc_J
            if jac is not None:
                mujoco.mj_jacSite(m, d, jac[i], None, self._tcp)
        if jac is not None and external is not None:
            tau -= np.einsum("tij,ti->tj", jac, external)
        loop = efc.reshape(T, 6, nv)[:, self._loop_rows]
        lam = np.linalg.solve(
            np.swapaxes(loop[:, :, self._dependent], 1, 2), tau[:, self._dependent, None]
        )  # lambda = J_d^-T tau_d
        force = tau[:, self._slides] - np.einsum("tra,tr->ta", loop[:, :, self._slides], lam[:, :, 0])
        return ActuatorSamples(
            force=force,
            velocity=qvel[:, self._slides],
            acceleration=qacc[:, self._slides],
            stroke=qpos[:, self._slides],
        )

    def energy(self, joints: JointSamples) -> tuple[Array, Array]:
        """Potential and kinetic energy [J] along the samples, (T,) each (``mj_energyPos``/``mj_energyVel``).

        The potential is gravity's, zero at the world origin; the state is the loop-consistent
        one of :meth:`state`.
        """
        qpos, qvel, _ = self.state(joints)
        return mechanical_energies(self.model, self.data, qpos, qvel)


def mechanical_energy(crane: Crane, lengths: LinkLengths | None, joints: JointSamples) -> Array:
    """Total mechanical energy, kinetic + potential [J], (T,), along loop-consistent samples."""
    potential, kinetic = MujocoInverseDynamics(crane, lengths).energy(joints)
    return potential + kinetic

"""Pin forces from MuJoCo: the loop constraint forces at the rod ends and the bodies' interaction forces.

Along loop-consistent samples (:meth:`hiab_sim.dynamics.mujoco_id.MujocoInverseDynamics.state`),
``mj_inverse`` on the model with its ``connect`` equalities gives qfrc_inverse = M qacc + c -
qfrc_constraint, where qfrc_constraint is the soft loops' force for this qacc (not zero where
J qacc = -dJ qvel != 0); adding it back gives tau = M qacc + c - tau_ext, and
the loop Jacobian J (in-plane rows of ``efc_J``). As in :mod:`hiab_sim.dynamics.mujoco_id`, the
unactuated dofs d (every dof that no actuator drives) carry no generalised force, so the pin
forces of the loops are lambda = J_d^-T tau_d: the constraint applies +lambda to the rod at its
``<chain>_rod_end`` site and -lambda to the boom at ``<chain>_boom_pivot`` (qfrc_constraint =
J^T lambda with J = d(p_rod - p_boom)/dq), so the rod pushes the boom with P = -lambda.

The hinge forces are MuJoCo's own: on the same model with its constraints disabled (an open
tree), lambda and the TCP force are applied as body forces (``xfrc_applied``, at the sites),
and ``mj_rnePostConstraint`` gives ``cfrc_int``, the wrench every body receives from its parent
through its joint. Its force part on a chain's cylinder is the base pivot force, on its boom
the hinge force; the bracket receives their opposites. Forces are mapped from MuJoCo's world
back to the source frame {W} (:data:`hiab_sim.model.mjcf.SOURCE_TO_WORLD`).
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.checks import tcp_force_samples
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.model.mjcf import SOURCE_TO_WORLD, source_to_world
from hiab_sim.structure.pin_loads import CHAIN_PINS, PinLoads, chain_links, pins


class MujocoPinLoads:
    """Pin forces of one link-length set by MuJoCo (see the module docstring); build once, call many times."""

    def __init__(self, crane: Crane, lengths: LinkLengths | None = None) -> None:
        self.crane = crane
        self.inverse = MujocoInverseDynamics(crane, lengths)
        m = self.inverse.model
        self.model = m
        self.data = mujoco.MjData(m)
        self._open = copy.copy(m)
        self._open.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
        self._open_data = mujoco.MjData(self._open)
        actuated = {int(m.jnt_dofadr[m.actuator_trnid[a, 0]]) for a in range(m.nu)}
        self._dependent = np.array([v for v in range(m.nv) if v not in actuated])
        self._axis = self._hinge_axis()
        in_plane = np.flatnonzero(np.abs(self._axis) < 0.5)
        self._chains = [c.name for c in crane.chains]
        eq_rows = [3 * m.equality(f"{c}_loop").id for c in self._chains]
        self._loop_rows = np.concatenate([row + in_plane for row in eq_rows])
        self._in_plane = in_plane
        self._rod_end = [m.site(f"{c}_rod_end").id for c in self._chains]
        self._boom_pivot = [m.site(f"{c}_boom_pivot").id for c in self._chains]
        self._bodies = [[m.body(name).id for name in chain_links(c)] for c in self._chains]
        self._tcp = m.site("tcp").id

    def _hinge_axis(self) -> Array:
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        hinges = [j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
        axis: Array = d.xaxis[hinges[0]].copy()
        return axis

    def __call__(self, joints: JointSamples, tcp_force: ArrayLike | None = None) -> PinLoads:
        """Pin forces [N] along the samples; ``tcp_force`` [N] in {W}, (3,) or (T, 3)."""
        T = len(joints)
        samples = tcp_force_samples(tcp_force, T)
        external = None if samples is None else source_to_world(samples)
        qpos, qvel, qacc = self.inverse.state(joints)
        m, d, mo, do = self.model, self.data, self._open, self._open_data
        n_pins = len(CHAIN_PINS) * len(self._chains)
        world = np.zeros((T, n_pins, 3))
        frames = np.zeros((T, n_pins, 3, 3))
        jac = np.zeros((3, m.nv))
        for i in range(T):
            d.qpos[:], d.qvel[:], d.qacc[:] = qpos[i], qvel[i], qacc[i]
            mujoco.mj_inverse(m, d)
            tau = d.qfrc_inverse + d.qfrc_constraint  # M qacc + c: the soft loops' own force is not subtracted
            if external is not None:
                mujoco.mj_jacSite(m, d, jac, None, self._tcp)
                tau -= jac.T @ external[i]
            loop = d.efc_J.reshape(-1, m.nv)[self._loop_rows]
            lam = np.linalg.solve(loop[:, self._dependent].T, tau[self._dependent])
            do.qpos[:], do.qvel[:], do.qacc[:] = qpos[i], qvel[i], qacc[i]
            do.xfrc_applied[:] = 0.0
            mujoco.mj_kinematics(mo, do)
            for c in range(len(self._chains)):
                force = np.zeros(3)
                force[self._in_plane] = lam[2 * c : 2 * c + 2]
                _, _, rod = self._bodies[c]
                boom = self._bodies[c][0]
                self._apply(rod, do.site_xpos[self._rod_end[c]], force)
                self._apply(boom, do.site_xpos[self._boom_pivot[c]], -force)
                world[i, 3 * c + 2] = -force
            if external is not None:
                self._apply(int(mo.site_bodyid[self._tcp]), do.site_xpos[self._tcp], external[i])
            mujoco.mj_inverse(mo, do)
            mujoco.mj_rnePostConstraint(mo, do)
            for c in range(len(self._chains)):
                boom, cylinder, _ = self._bodies[c]
                world[i, 3 * c] = -do.cfrc_int[cylinder, 3:]
                world[i, 3 * c + 1] = -do.cfrc_int[boom, 3:]
                parent = int(mo.body_parentid[boom])
                frames[i, 3 * c : 3 * c + 2] = do.xmat[parent].reshape(3, 3)
                frames[i, 3 * c + 2] = do.xmat[boom].reshape(3, 3)
        source = world @ SOURCE_TO_WORLD  # world -> {W}: v_src = R^T v_world
        local = np.einsum("tpji,tpj->tpi", frames, world)
        # the bracket frames' x-y plane is the source plane: map their local (x, y, z) as is
        return PinLoads(pins(self.crane), source[..., :2], local[..., :2])

    def _apply(self, body: int, point: Array, force: Array) -> None:
        """Add a force [N] at a world point to a body of the open model (at its com, with the moment)."""
        d = self._open_data
        d.xfrc_applied[body, :3] += force
        d.xfrc_applied[body, 3:] += np.cross(point - d.xipos[body], force)

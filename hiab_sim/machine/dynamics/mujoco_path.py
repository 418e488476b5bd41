"""MuJoCo inverse dynamics of any machine with the loop projection: actuator and pin forces per sample.

``MujocoMachineDynamics(machine)(q, dq, ddq, tcp_force)`` maps samples of the independent joints to
the actuator forces f_x [N] (> 0 extends), their velocities and strokes, and the force on every
pin, on the MJCF model of :mod:`hiab_sim.machine.dynamics.mjcf_build` (built once per design). Per sample:

1. **Loop-consistent state from MuJoCo's kinematics.** The closed-form closure of
   :func:`hiab_sim.machine.dynamics.planar.close_loops` is the first guess; Newton steps on
   MuJoCo's own pin residuals C = p_a - p_b (sites ``<pin>.a``, ``<pin>.b``, in-plane rows, Jacobian
   ``mj_jacSite``) bring |C| below 1e-13 m. The rates follow from MuJoCo's Jacobians J = [J_i, J_d]:
   J_d dq_d = -J_i dq_i, J_d ddq_d = -(J_i ddq_i + dJ dq) with dJ dq from ``mj_jacDot``.
2. **Inverse dynamics and projection.** ``mj_inverse`` on the model with constraints disabled gives
   tau = M ddq + c - tau_passive of the open tree (with the simulation extras, M holds the
   armature and tau_passive the damping); the TCP force enters as tau_ext = J_tcp^T F. The closed
   machine's balance is

       tau - J_tcp^T F = S^T f + J^T lambda,

   with S selecting the actuated joints and lambda (2 per pin) the force body b applies to body a at
   each loop pin (J^T lambda is its generalised force). With every joint driven, [S^T J^T] is
   square (nv x nv): one solve gives f and lambda. This is the principle of virtual power on the
   admissible motions plus the pin forces; the soft ``connect`` model never enters.
3. **Hinge pin forces.** With lambda and the TCP force applied to their bodies (``xfrc_applied``),
   ``mj_rnePostConstraint`` gives ``cfrc_int``, the force every body's parent applies to it through
   its joint; for a hinge that is the pin force.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.mjcf_build import SimulationExtras, spec_of_tree
from hiab_sim.machine.dynamics.planar import close_loops, planar_bodies
from hiab_sim.machine.dynamics.tree import (
    MachineActuatorSamples,
    PinForces,
    joint_arrays,
    machine_tree,
    pin_layout,
    tcp_force_array,
)
from hiab_sim.model.states import mechanical_energies

#: Rows of a MuJoCo world vector that lie in the machine's plane (x, y) = MuJoCo (x, z).
_PLANE = [0, 2]
#: Newton iterations and residual tolerance [m] of the loop polish (quadratic: 1-2 steps suffice).
_NEWTON_STEPS = 8
_NEWTON_TOL = 1e-13


class MujocoMachineDynamics:
    """MuJoCo inverse dynamics of one machine design, reusable (see the module docstring).

    Args:
        machine: The machine description.
        design: Decision variable values (default: the file's).
        extras: Armature and damping of the simulation model (default: the bare mechanism,
            load-side forces).

    """

    def __init__(self, machine: Machine, design: Sequence[float] | None = None, extras: SimulationExtras | None = None):
        if design is not None:
            machine = machine.with_design(design)
        self.tree = machine_tree(machine)
        self._planar = planar_bodies(self.tree)
        self.model = spec_of_tree(self.tree, extras).compile()
        self.model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
        self.data = mujoco.MjData(self.model)
        m, tree = self.model, self.tree
        self._adr = np.array([int(m.joint(body.joint).dofadr[0]) for body in tree.bodies[1:]])
        self._ind = self._adr[[b - 1 for b in tree.independent]]
        self._dep = self._adr[[b - 1 for b in tree.dependent]]
        self._act = self._adr[[b - 1 for b in tree.actuated]]
        self._sites = [(m.site(f"{p.name}.a").id, m.site(f"{p.name}.b").id) for p in tree.loops]
        self._tcp = m.site("tcp").id
        self._body = np.array([m.body(body.name).id for body in tree.bodies])
        self._pins = pin_layout(tree)
        #: sites where forces act in the pin pass (each pin's two sites, then the TCP), their bodies,
        #: and the body each reported force acts on
        self._force_sites = np.array([*(s for pair in self._sites for s in pair), self._tcp])
        self._force_bodies = m.site_bodyid[self._force_sites]
        self._on = self._body[[*range(1, len(tree.bodies)), *(p.body_a for p in tree.loops)]]
        if m.nq != m.nv:
            raise AssertionError("a planar machine has only hinges and slides")
        # the balance matrix [S^T J^T]: S^T's columns are fixed
        self._select = np.zeros((m.nv, len(self._act)))
        self._select[self._act, np.arange(len(self._act))] = 1.0

    # ------------------------------------------------------------------------------------------

    def _loop_residual(self) -> tuple[Array, Array]:
        """In-plane pin residuals (2 n_pins,) and their Jacobian (2 n_pins, nv) at the data's qpos."""
        m, d = self.model, self.data
        residual = np.empty(2 * len(self._sites))
        jac = np.empty((2 * len(self._sites), m.nv))
        ja, jb = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        for k, (a, b) in enumerate(self._sites):
            mujoco.mj_jacSite(m, d, ja, None, a)
            mujoco.mj_jacSite(m, d, jb, None, b)
            residual[2 * k : 2 * k + 2] = (d.site_xpos[a] - d.site_xpos[b])[_PLANE]
            jac[2 * k : 2 * k + 2] = (ja - jb)[_PLANE]
        return residual, jac

    def _jac_dot_dq(self) -> Array:
        """dJ/dt dq of the pin residuals (2 n_pins,) at the data's qpos, qvel (``mj_jacDot``)."""
        m, d = self.model, self.data
        out = np.empty(2 * len(self._sites))
        ja, jb = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        for k, (a, b) in enumerate(self._sites):
            mujoco.mj_jacDot(m, d, ja, None, d.site_xpos[a], m.site_bodyid[a])
            mujoco.mj_jacDot(m, d, jb, None, d.site_xpos[b], m.site_bodyid[b])
            out[2 * k : 2 * k + 2] = ((ja - jb) @ d.qvel)[_PLANE]
        return out

    def _set_state(self, qpos: Array, dq: Array, ddq: Array) -> tuple[Array, Array, Array]:
        """Polish qpos on the loops, solve the dependent rates; leaves the full state in ``data``."""
        m, d = self.model, self.data
        d.qpos[:] = qpos
        d.qvel[:] = 0.0
        d.qacc[:] = 0.0
        residual = np.zeros(0)
        jac = np.zeros((0, m.nv))
        for _ in range(_NEWTON_STEPS):
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            residual, jac = self._loop_residual()
            if residual.size == 0 or np.max(np.abs(residual)) < _NEWTON_TOL:
                break
            d.qpos[self._dep] -= np.linalg.solve(jac[:, self._dep], residual)
        else:
            raise AssertionError(f"the loops did not close: |C| = {np.max(np.abs(residual)):.3g} m")
        d.qvel[self._ind] = dq
        d.qacc[self._ind] = ddq
        if residual.size:
            jd = jac[:, self._dep]
            d.qvel[self._dep] = np.linalg.solve(jd, -jac[:, self._ind] @ dq)
            mujoco.mj_comVel(m, d)
            d.qacc[self._dep] = np.linalg.solve(jd, -(jac[:, self._ind] @ ddq + self._jac_dot_dq()))
        return jac, d.qvel.copy(), d.qacc.copy()

    def state(self, q: Any, dq: Any, ddq: Any) -> tuple[Array, Array, Array]:
        """Loop-consistent (qpos, qvel, qacc), each (T, nv) in MuJoCo's dof order; inputs checked."""
        q, dq, ddq = joint_arrays(self.tree, q, dq, ddq)
        seed = close_loops(self.tree, self._planar, q)
        T, nv = q.shape[0], self.model.nv
        out = np.empty((3, T, nv))
        for i in range(T):
            qpos = np.zeros(nv)
            qpos[self._adr] = seed[i, 1:]
            _, out[1, i], out[2, i] = self._set_state(qpos, dq[i], ddq[i])
            out[0, i] = self.data.qpos
        return out[0], out[1], out[2]

    #: ``__call__(..., pins=False)`` leaves the pin forces out
    can_skip_pins = True

    def __call__(
        self, q: Any, dq: Any, ddq: Any, tcp_force: Any = None, *, pins: bool = True
    ) -> MachineActuatorSamples:
        """Actuator forces, velocities, accelerations, strokes (T, n_chains) and pin forces.

        Args, units and sign conventions as :class:`hiab_sim.machine.dynamics.newton_euler.NewtonEulerInverseDynamics`;
        ``pins`` False leaves the pin forces out (their arrays are NaN: a caller that needs only the actuators,
        e.g. the optimiser's partials, skips ``mj_rnePostConstraint`` per sample).
        """
        q, dq, ddq = joint_arrays(self.tree, q, dq, ddq)
        T = q.shape[0]
        external = tcp_force_array(tcp_force, T)
        seed = close_loops(self.tree, self._planar, q)
        m, d = self.model, self.data
        n_act, n_pin = len(self._act), len(self._pins[0])
        force, velocity, acceleration, stroke = (np.empty((T, n_act)) for _ in range(4))
        world = np.empty((T, n_pin, 2))
        local = np.empty((T, n_pin, 3))
        jtcp = np.zeros((3, m.nv))
        for i in range(T):
            qpos = np.zeros(m.nv)
            qpos[self._adr] = seed[i, 1:]
            jac, qvel, qacc = self._set_state(qpos, dq[i], ddq[i])
            mujoco.mj_inverse(m, d)
            tau = d.qfrc_inverse.copy()
            f_ext = np.array([external[i, 0], 0.0, external[i, 1]])  # MuJoCo world
            mujoco.mj_jacSite(m, d, jtcp, None, self._tcp)
            tau -= jtcp.T @ f_ext
            solution = np.linalg.solve(np.hstack([self._select, jac.T]), tau)
            force[i] = solution[:n_act]
            lam = solution[n_act:].reshape(-1, 2)
            velocity[i], acceleration[i], stroke[i] = qvel[self._act], qacc[self._act], d.qpos[self._act]
            if pins:
                world[i], local[i] = self._pin_forces(lam, f_ext)
        if not pins:
            world[:], local[:] = np.nan, np.nan
        names, kinds, on, by = self._pins
        return MachineActuatorSamples(
            names=tuple(self.tree.machine.actuator_names),
            force=force,
            velocity=velocity,
            acceleration=acceleration,
            stroke=stroke,
            pins=PinForces(names=names, kinds=kinds, on=on, by=by, world=world, local=local),
        )

    def _pin_forces(self, lam: Array, f_ext: Array) -> tuple[Array, Array]:
        """World (P, 2) and body-frame (P, 3) forces: joints from ``cfrc_int``, loop pins = lambda."""
        m, d = self.model, self.data
        n = len(self._sites)
        forces = np.zeros((2 * n + 1, 3))
        forces[0 : 2 * n : 2, 0::2] = lam  # on body a at its site
        forces[1 : 2 * n : 2, 0::2] = -lam  # on body b at its site
        forces[-1] = f_ext
        arm = d.site_xpos[self._force_sites] - d.xipos[self._force_bodies]
        d.xfrc_applied[:] = 0.0  # (force, torque about the body's com) per body
        np.add.at(d.xfrc_applied, self._force_bodies, np.hstack([forces, np.cross(arm, forces)]))
        mujoco.mj_rnePostConstraint(m, d)
        d.xfrc_applied[:] = 0.0
        world = np.vstack([d.cfrc_int[self._body[1:], 3:][:, _PLANE], lam])
        planar = np.zeros((len(world), 3))
        planar[:, 0::2] = world
        rotation = d.xmat[self._on].reshape(-1, 3, 3)  # body frames keep the description's axes
        return world, np.einsum("pji,pj->pi", rotation, planar)

    # ------------------------------------------------------------------------------------------

    def energy(self, q: Any, dq: Any) -> tuple[Array, Array]:
        """Kinetic and potential energy [J], (T,) each (``mj_energyVel``, ``mj_energyPos``), zero at y = 0."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        qpos, qvel, _ = self.state(q, dq, np.zeros_like(q))
        potential, kinetic = mechanical_energies(self.model, self.data, qpos, qvel)
        return kinetic, potential

"""Analytic inverse dynamics of any planar parallel-serial machine: Newton-Euler on the link tree, numpy only.

Written independently of MuJoCo. For each sample the loop-consistent motion of every body comes
from :mod:`hiab_sim.machine.dynamics.planar`; each moving body b of the tree
(:mod:`hiab_sim.machine.dynamics.tree`) is then cut free at its joint and at its loop pins. Its
planar Newton-Euler equations, in the world with moments about the world origin (Lynch & Park
eq. 8.41 restricted to se(2)), fix what the forces on it must add up to:

    (F, M_O)_b = ( m_b (a_c - g),  I_zz,b alpha_b + c_b x m_b (a_c - g) ),   g = (0, -g).

The force (and moment) that body b's joint transmits from its parent follows tip to base, the
backward pass of recursive Newton-Euler:

    T_b = (F, M_O)_b - (TCP force on b) - sum (loop pin forces on b) + sum_children T_c,

with the force lambda (2 per loop pin) that body b of a pin applies to its body a (and -lambda
on b) still unknown: every T_b is affine in lambda. The unknowns follow from the joints that
carry no moment: each unactuated revolute joint's moment about its pin vanishes,

    M_O(T_b) - o_b x F(T_b) = 0   for every revolute joint b,

one equation each. With every moving joint driven by one chain (all prismatic joints are the
actuators) there are exactly as many hinges as loop-pin force components, so this system
(2 n_pins square, per sample) gives lambda; then every T_b is known: a hinge's T_b is its pin
force, a slide's axial component u . F(T_b) is the actuator force f_x (> 0 extends). It is
regular away from a flat triangle or a four-bar at its toggle. The MuJoCo path
(:mod:`hiab_sim.machine.dynamics.mujoco_path`) instead projects MuJoCo's generalised forces on the
loops' admissible motions.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.planar import Frames, PlanarBody, frames, loop_state, planar_bodies
from hiab_sim.machine.dynamics.tree import (
    MachineActuatorSamples,
    MachineTree,
    PinForces,
    SimulationExtras,
    joint_arrays,
    machine_tree,
    pin_layout,
    tcp_force_array,
)

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]


def _cross(a: Complex | complex, b: Complex | complex) -> Array:
    """The z component of the cross product of in-plane vectors (complex)."""
    return (np.conj(a) * b).imag


class NewtonEulerInverseDynamics:
    """Inverse dynamics of one machine design by per-body Newton-Euler (see the module docstring).

    Args:
        machine: The machine description.
        design: Decision variable values (default: the file's), as :meth:`Machine.with_design`.
        extras: Armature and damping per actuator: the forces become the motor side,
            f_x + (J_m k^2 + M_sm) a_x + b_f v_x (eqs. ``torque_torque``, ``torque_force``); pin
            forces stay those of the mechanism. Default: the bare mechanism (load side).

    Raises:
        InvalidInputError: a moving joint that no chain drives, a design outside its bounds,
            extras of the wrong length.

    """

    def __init__(
        self, machine: Machine, design: Sequence[float] | None = None, extras: SimulationExtras | None = None
    ) -> None:
        if design is not None:
            machine = machine.with_design(design)
        if extras is not None and len(extras.armature_kg) != len(machine.chains):
            need = f"need one per actuator: {machine.actuator_names}"
            raise InvalidInputError("extras.armature_kg", f"{len(extras.armature_kg)} values", need)
        self.extras = extras
        self.tree: MachineTree = machine_tree(machine)
        self.planar: tuple[PlanarBody, ...] = planar_bodies(self.tree)
        self._pins = pin_layout(self.tree)
        self._hinges = [b for b, body in enumerate(self.tree.bodies) if body.kind == "revolute"]
        if len(self._hinges) != 2 * len(self.tree.loops):
            raise AssertionError("a fully driven tree has one hinge per loop-pin force component")

    def state(self, q: Any, dq: Any, ddq: Any) -> tuple[Array, Array, Array]:
        """Loop-consistent full coordinates, rates, accelerations (T, nbody); inputs checked."""
        q, dq, ddq = joint_arrays(self.tree, q, dq, ddq)
        return loop_state(self.tree, self.planar, q, dq, ddq)

    def __call__(self, q: Any, dq: Any, ddq: Any, tcp_force: Any = None) -> MachineActuatorSamples:
        """Actuator forces, velocities, accelerations, strokes (T, n_chains) and pin forces.

        Args:
            q: Independent joint positions (T, n) in :attr:`Machine.joint_names` order [rad or m].
            dq: Their rates (T, n).
            ddq: Their accelerations (T, n).
            tcp_force: Force the environment applies at the TCP in the world plane [N], (2,) or
                (T, 2); a payload of mass m is (0, -m g). Default none.

        Raises:
            InvalidInputError: malformed or out-of-range joint samples or tcp_force (named field).

        """
        qf, dqf, ddqf = self.state(q, dq, ddq)
        T = qf.shape[0]
        external = tcp_force_array(tcp_force, T)
        fk = frames(self.tree, self.planar, qf, dqf, ddqf)
        transmitted, lam = self._joint_forces(fk, external[:, 0] + 1j * external[:, 1])
        act = list(self.tree.actuated)
        force = np.stack([(np.conj(self._axis(fk, b)) * transmitted[b]).real for b in act], axis=1)
        if self.extras is not None:
            force = force + np.asarray(self.extras.armature_kg) * ddqf[:, act]
            force = force + np.asarray(self.extras.damping_Ns_per_m) * dqf[:, act]
        return MachineActuatorSamples(
            names=tuple(self.tree.machine.actuator_names),
            force=force,
            velocity=dqf[:, act],
            acceleration=ddqf[:, act],
            stroke=qf[:, act],
            pins=self._pin_forces(fk, transmitted, lam),
        )

    # ------------------------------------------------------------------------------------------

    def _axis(self, fk: Frames, b: int) -> Complex:
        """World direction of body b's slide (T,)."""
        return fk.rot[self.tree.bodies[b].parent] * self.planar[b].axis

    def _joint_forces(self, fk: Frames, external: Complex) -> tuple[list[Complex], Array]:
        """Force each joint transmits from parent to body (complex (T,), index = body) and lambda (T, 2 n_pins)."""
        tree, planar = self.tree, self.planar
        T, n, pins = fk.z[0].shape[0], len(tree.bodies), 2 * len(tree.loops)
        # T_b = base + coefficient @ lambda, force (complex) and moment about O, per body
        force = [np.zeros(T, dtype=complex) for _ in range(n)]
        moment = [np.zeros(T) for _ in range(n)]
        force_per = [np.zeros((T, pins), dtype=complex) for _ in range(n)]
        moment_per = [np.zeros((T, pins)) for _ in range(n)]
        for b in range(1, n):
            p = planar[b]
            if p.mass > 0.0 or p.inertia_zz > 0.0:
                com, _, acc = fk.point(b, p.com)
                net = p.mass * (acc + 1j * tree.gravity)
                force[b] += net
                moment[b] += p.inertia_zz * fk.alpha[b] + _cross(com, net)
        tcp = fk.point(tree.tcp_body, planar[tree.tcp_body].point(np.asarray(tree.tcp.position)))[0]
        force[tree.tcp_body] -= external
        moment[tree.tcp_body] -= _cross(tcp, external)
        for k, loop in enumerate(tree.loops):
            on_a = fk.point(loop.body_a, planar[loop.body_a].point(loop.point_a))[0]
            on_b = fk.point(loop.body_b, planar[loop.body_b].point(loop.point_b))[0]
            for j, unit in enumerate((1.0 + 0j, 1j)):  # lambda_x, lambda_y
                force_per[loop.body_a][:, 2 * k + j] -= unit
                moment_per[loop.body_a][:, 2 * k + j] -= _cross(on_a, unit)
                force_per[loop.body_b][:, 2 * k + j] += unit
                moment_per[loop.body_b][:, 2 * k + j] += _cross(on_b, unit)
        for b in range(n - 1, 0, -1):  # parents precede children: add each body's joint into its parent's
            parent = tree.bodies[b].parent
            if parent > 0:
                force[parent] += force[b]
                moment[parent] += moment[b]
                force_per[parent] += force_per[b]
                moment_per[parent] += moment_per[b]
        rows = np.stack([moment_per[b] - _cross(fk.z[b][:, None], force_per[b]) for b in self._hinges], axis=1)
        rhs = np.stack([_cross(fk.z[b], force[b]) - moment[b] for b in self._hinges], axis=1)
        lam = np.asarray(np.linalg.solve(rows, rhs[..., None])[..., 0], dtype=float)
        transmitted = [force[b] + np.einsum("tl,tl->t", force_per[b], lam) for b in range(n)]
        return transmitted, lam

    def _pin_forces(self, fk: Frames, transmitted: list[Complex], lam: Array) -> PinForces:
        """World and body-frame forces of every joint and loop pin."""
        tree = self.tree
        world = [np.stack([transmitted[b].real, transmitted[b].imag], axis=1) for b in range(1, len(tree.bodies))]
        world.extend(lam[:, 2 * k : 2 * k + 2] for k in range(len(tree.loops)))
        on_body = [*range(1, len(tree.bodies)), *(loop.body_a for loop in tree.loops)]
        world_array = np.stack(world, axis=1)
        local = np.empty((*world_array.shape[:2], 3))
        for k, b in enumerate(on_body):
            local[:, k] = _to_body_frame(self.planar[b].fixed, fk.theta[b], world_array[:, k])
        names, kinds, on, by = self._pins
        return PinForces(names=names, kinds=kinds, on=on, by=by, world=world_array, local=local)

    # ------------------------------------------------------------------------------------------

    def energy(self, q: Any, dq: Any) -> tuple[Array, Array]:
        """Kinetic and potential energy [J], (T,) each, at loop-consistent states (potential zero at y = 0)."""
        zero = np.zeros_like(np.atleast_2d(np.asarray(q, dtype=float)))
        qf, dqf, _ = self.state(q, dq, zero)
        return self.energy_of_full(qf, dqf)

    def energy_of_full(self, qf: Array, dqf: Array) -> tuple[Array, Array]:
        """Kinetic and potential energy [J] of full coordinates (T, nbody) with no range checks."""
        fk = frames(self.tree, self.planar, qf, dqf, np.zeros_like(qf))
        kinetic = np.zeros(qf.shape[0])
        potential = np.zeros(qf.shape[0])
        for b, p in enumerate(self.planar):
            if b == 0:
                continue
            com, velocity, _ = fk.point(b, p.com)
            kinetic += 0.5 * (p.mass * np.abs(velocity) ** 2 + p.inertia_zz * fk.omega[b] ** 2)
            potential += p.mass * self.tree.gravity * com.imag
        return kinetic, potential

    def tcp_velocity(self, q: Any, dq: Any) -> Array:
        """Velocity of the TCP point in the world plane (T, 2) [m/s] (the power of a TCP force)."""
        zero = np.zeros_like(np.atleast_2d(np.asarray(q, dtype=float)))
        qf, dqf, ddqf = self.state(q, dq, zero)
        fk = frames(self.tree, self.planar, qf, dqf, ddqf)
        b = self.tree.tcp_body
        v = fk.point(b, self.planar[b].point(np.asarray(self.tree.tcp.position)))[1]
        return np.stack([v.real, v.imag], axis=1)


def _to_body_frame(fixed: Array, theta: Array, force: Array) -> Array:
    """World in-plane force (T, 2) in the axes of a body frame Rz(theta) F: F^T Rz(-theta) [f; 0], (T, 3)."""
    c, s = np.cos(theta), np.sin(theta)
    rotated = np.stack([c * force[:, 0] + s * force[:, 1], -s * force[:, 0] + c * force[:, 1], np.zeros_like(c)], 1)
    return rotated @ fixed

"""Analytic inverse dynamics of any planar parallel-serial machine: Newton-Euler of every body, numpy only.

Written independently of MuJoCo. For each sample the loop-consistent motion of every body comes
from :mod:`hiab_sim.machine.dynamics_planar`; then each moving body b of the tree
(:mod:`hiab_sim.machine.dynamics_tree`) is cut free and its planar Newton-Euler equations are
written in the world, moments about the world origin (Lynch & Park eq. 8.41 restricted to se(2)):

    sum F   = m_b (a_c - g),                 g = (0, -g) [m/s^2]
    sum M_O = I_zz,b alpha_b + c_b x m_b (a_c - g),

where the forces on the body are its unknown joint and pin forces and the known external force
at the TCP. The unknowns, per sample:

* each revolute joint: the pin force R (2) the parent applies to the child at the joint origin
  (the parent gets -R); an unactuated hinge carries no moment about the plane normal;
* each prismatic joint: the actuator force f along the slide axis u (the seed's f_x: > 0
  extends), and the constraint force N along i u and moment M, all applied at the child's frame
  origin (the parent gets the opposite);
* each loop pin: the force lambda (2) body b applies to body a at the pin (body b gets -lambda).

With every moving joint driven by one chain the unknowns are exactly three per moving body, so
the system A(q) u = b (3 n x 3 n per sample) is square and is solved for all samples at once
(``numpy.linalg.solve``); it is regular away from a flat triangle or a four-bar at its toggle.
This yields the actuator forces and every pin force in one solve, with no Jacobian projection
(the MuJoCo path, :mod:`hiab_sim.machine.dynamics_mujoco`, projects instead).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics_planar import Frames, PlanarBody, frames, loop_state, planar_bodies
from hiab_sim.machine.dynamics_tree import (
    MachineActuatorSamples,
    MachineTree,
    PinForces,
    joint_arrays,
    machine_tree,
    pin_layout,
    tcp_force_array,
)

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]


def _cross(a: Complex, b: Complex) -> Array:
    """The z component of the cross product of in-plane vectors (complex)."""
    return (np.conj(a) * b).imag


class NewtonEulerInverseDynamics:
    """Inverse dynamics of one machine design by per-body Newton-Euler (see the module docstring).

    Args:
        machine: The machine description.
        design: Decision variable values (default: the file's), as :meth:`Machine.with_design`.

    Raises:
        InvalidInputError: a moving joint that no chain drives, a design outside its bounds.

    """

    def __init__(self, machine: Machine, design: Sequence[float] | None = None) -> None:
        if design is not None:
            machine = machine.with_design(design)
        self.tree: MachineTree = machine_tree(machine)
        self.planar: tuple[PlanarBody, ...] = planar_bodies(self.tree)
        self._pins = pin_layout(self.tree)
        bodies = self.tree.bodies
        self._moving = list(range(1, len(bodies)))
        self._row = {b: 3 * k for k, b in enumerate(self._moving)}
        columns: dict[int, int] = {}
        size = 0
        for b in self._moving:
            columns[b] = size
            size += 2 if bodies[b].kind == "revolute" else 3
        self._joint_column = columns
        self._loop_column = [size + 2 * k for k in range(len(self.tree.loops))]
        self._size = size + 2 * len(self.tree.loops)
        if self._size != 3 * len(self._moving):
            raise AssertionError("a fully driven tree has three unknowns per moving body")

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
        A, rhs = self._system(fk, external[:, 0] + 1j * external[:, 1])
        u = np.linalg.solve(A, rhs[..., None])[..., 0]
        act = list(self.tree.actuated)
        force = np.stack([u[:, self._joint_column[b]] for b in act], axis=1)
        return MachineActuatorSamples(
            names=tuple(self.tree.machine.actuator_names),
            force=force,
            velocity=dqf[:, act],
            acceleration=ddqf[:, act],
            stroke=qf[:, act],
            pins=self._pin_forces(fk, u),
        )

    # ------------------------------------------------------------------------------------------

    def _system(self, fk: Frames, external: Complex) -> tuple[Array, Array]:
        """The stacked Newton-Euler equations A u = b, (T, 3n, 3n) and (T, 3n)."""
        tree, planar = self.tree, self.planar
        T = fk.z[0].shape[0]
        A = np.zeros((T, self._size, self._size))
        rhs = np.zeros((T, self._size))

        def put(body: int, column: int, force: Complex | complex, point: Complex, moment: float = 0.0) -> None:
            """Add unit unknown ``column``'s force on ``body`` at ``point`` (and a pure moment)."""
            if body == 0:
                return  # the root is held by the world: its equations are not written
            r = self._row[body]
            f = np.broadcast_to(np.asarray(force, dtype=complex), (T,))
            A[:, r, column] += f.real
            A[:, r + 1, column] += f.imag
            A[:, r + 2, column] += _cross(point, f) + moment

        for b in self._moving:
            body, c = tree.bodies[b], self._joint_column[b]
            origin = fk.z[b]
            if body.kind == "revolute":
                for k, direction in enumerate((1.0 + 0j, 1j)):
                    put(b, c + k, direction, origin)
                    put(body.parent, c + k, -direction, origin)
            else:
                u = np.exp(1j * fk.theta[body.parent]) * planar[b].axis
                for k, direction in enumerate((u, 1j * u)):
                    put(b, c + k, direction, origin)
                    put(body.parent, c + k, -direction, origin)
                put(b, c + 2, 0j, origin, 1.0)
                put(body.parent, c + 2, 0j, origin, -1.0)
            # Newton-Euler: what the forces on the body must add up to
            p = planar[b]
            if p.mass > 0.0 or p.inertia_zz > 0.0:
                com, _, acc = fk.point(b, p.com)
                net = p.mass * (acc + 1j * tree.gravity)
                r = self._row[b]
                rhs[:, r] += net.real
                rhs[:, r + 1] += net.imag
                rhs[:, r + 2] += p.inertia_zz * fk.alpha[b] + _cross(com, net)
        for loop, c in zip(tree.loops, self._loop_column, strict=True):
            pa = fk.point(loop.body_a, planar[loop.body_a].point(loop.point_a))[0]
            pb = fk.point(loop.body_b, planar[loop.body_b].point(loop.point_b))[0]
            for k, direction in enumerate((1.0 + 0j, 1j)):
                put(loop.body_a, c + k, direction, pa)
                put(loop.body_b, c + k, -direction, pb)
        tcp = fk.point(tree.tcp_body, planar[tree.tcp_body].point(np.asarray(tree.tcp.position)))[0]
        if tree.tcp_body != 0:
            r = self._row[tree.tcp_body]
            rhs[:, r] -= external.real
            rhs[:, r + 1] -= external.imag
            rhs[:, r + 2] -= _cross(tcp, external)
        return A, rhs

    def _pin_forces(self, fk: Frames, u: NDArray[np.floating[Any]]) -> PinForces:
        """World and body-frame forces of every pin from the solved unknowns."""
        tree = self.tree
        world = []
        on_body = []
        for b in self._moving:
            c = self._joint_column[b]
            if tree.bodies[b].kind == "revolute":
                world.append(u[:, c : c + 2])
            else:  # axial (actuator) and normal force along u and i u
                axis = np.exp(1j * fk.theta[tree.bodies[b].parent]) * self.planar[b].axis
                total = axis * (u[:, c] + 1j * u[:, c + 1])
                world.append(np.stack([total.real, total.imag], axis=1))
            on_body.append(b)
        for loop, c in zip(tree.loops, self._loop_column, strict=True):
            world.append(u[:, c : c + 2])
            on_body.append(loop.body_a)
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

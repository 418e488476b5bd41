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
regular away from a flat triangle or a four-bar at its toggle.

The solve is vectorised over samples and designs (:mod:`hiab_sim.machine.dynamics.ne_kernel`):
what no design changes is built once per machine (:mod:`hiab_sim.machine.dynamics.ne_layout`),
a design's numbers come from :mod:`hiab_sim.machine.dynamics.ne_design` without building its
tree, and :func:`batched_inverse_dynamics` evaluates D designs in one call. The MuJoCo path
(:mod:`hiab_sim.machine.dynamics.mujoco_path`) instead projects MuJoCo's generalised forces on the
loops' admissible motions.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.arrays import Array
from hiab_sim.checks import check_range
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.deferred_pins import DeferredPinForces
from hiab_sim.machine.dynamics.ne_design import design_constants
from hiab_sim.machine.dynamics.ne_forces import actuator_forces, joint_forces, pin_arrays
from hiab_sim.machine.dynamics.ne_kernel import frames_of_full, full_state
from hiab_sim.machine.dynamics.ne_layout import NeConstants, NeLayout, layout_of
from hiab_sim.machine.dynamics.ne_workspace import Prepared, prepare
from hiab_sim.machine.dynamics.planar import PlanarBody, planar_bodies
from hiab_sim.machine.dynamics.tree import (
    MachineActuatorSamples,
    MachineTree,
    SimulationExtras,
    joint_arrays,
    machine_tree,
    tcp_force_complex,
)


class NewtonEulerInverseDynamics:
    """Inverse dynamics of one machine design by per-body Newton-Euler (see the module docstring).

    Building one for a new design of the same machine object costs the design's bounds check
    and one vectorised pass of :func:`design_constants`; the designed machine itself
    (:attr:`machine`, with the rest of :meth:`Machine.with_design`'s checks) is built when first
    asked for.

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
        _check_extras(machine, extras)
        self.layout: NeLayout = layout_of(machine)
        self._file_machine, self._design = machine, None if design is None else _checked_design(machine, design)
        self.constants: NeConstants = self.layout.file
        if self._design is not None:
            self.constants = design_constants(machine, self.layout, self._design[None])
        self.prepared: Prepared = prepare(self.layout, self.constants)
        self.extras = extras

    @functools.cached_property
    def machine(self) -> Machine:
        """The designed machine, :meth:`Machine.with_design` (built on first use: the solve needs only its numbers)."""
        return self._file_machine if self._design is None else self._file_machine.with_design(self._design)

    @functools.cached_property
    def tree(self) -> MachineTree:
        """The designed machine's tree (built on first use)."""
        return self.layout.tree if self.machine is self.layout.tree.machine else machine_tree(self.machine)

    @functools.cached_property
    def planar(self) -> tuple[PlanarBody, ...]:
        """Planar data of the designed machine's bodies (built on first use)."""
        return planar_bodies(self.tree)

    def state(self, q: Any, dq: Any, ddq: Any) -> tuple[Array, Array, Array]:
        """Loop-consistent full coordinates, rates, accelerations (T, nbody); inputs checked."""
        q, dq, ddq = joint_arrays(self.layout.tree, q, dq, ddq)
        ws = full_state(self.layout, self.prepared, q.T[:, None], dq.T[:, None], ddq.T[:, None], angles=True)
        return ws.q[:, 0].T.copy(), ws.dq[:, 0].T.copy(), ws.ddq[:, 0].T.copy()

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
        layout = self.layout
        q, dq, ddq = joint_arrays(layout.tree, q, dq, ddq)
        external = tcp_force_complex(tcp_force, q.shape[0])
        ws = full_state(layout, self.prepared, q.T[:, None], dq.T[:, None], ddq.T[:, None])
        transmitted, _ = joint_forces(ws, self.prepared, external)
        pull = actuator_forces(ws, self.prepared, transmitted)
        # one (T, n) array each, filled row by row from the workspace (big blocks come fresh from the system)
        force, velocity, acceleration, stroke = (np.empty((q.shape[0], len(layout.actuated))) for _ in range(4))
        for k, b in enumerate(layout.actuated):
            force[:, k], velocity[:, k], acceleration[:, k], stroke[:, k] = (
                pull[k, 0],
                ws.dq[b, 0],
                ws.ddq[b, 0],
                ws.q[b, 0],
            )
        if self.extras is not None:
            force += (
                np.asarray(self.extras.armature_kg) * acceleration + np.asarray(self.extras.damping_Ns_per_m) * velocity
            )
        snapshot = (q.copy(), dq.copy(), ddq.copy())  # the pins are computed from these when first read
        names, kinds, on, by = layout.pins
        return MachineActuatorSamples(
            names=tuple(layout.tree.machine.actuator_names),
            force=force,
            velocity=velocity,
            acceleration=acceleration,
            stroke=stroke,
            pins=DeferredPinForces(names, kinds, on, by, lambda: self._pin_forces(snapshot, external)),
        )

    def _pin_forces(
        self, joints: tuple[Array, Array, Array], external: complex | NDArray[np.complex128] | None
    ) -> tuple[Array, Array]:
        """World (T, P, 2) and body-frame (T, P, 3) pin forces [N] at checked joints q, dq, ddq (T, n) each."""
        q, dq, ddq = (x.T[:, None] for x in joints)
        ws = full_state(self.layout, self.prepared, q, dq, ddq)
        transmitted, lam = joint_forces(ws, self.prepared, external)
        world, local = pin_arrays(ws, transmitted, lam)
        return world[0], local[0]

    # ------------------------------------------------------------------------------------------

    def energy(self, q: Any, dq: Any) -> tuple[Array, Array]:
        """Kinetic and potential energy [J], (T,) each, at loop-consistent states (potential zero at y = 0)."""
        zero = np.zeros_like(np.atleast_2d(np.asarray(q, dtype=float)))
        qf, dqf, _ = self.state(q, dq, zero)
        return self.energy_of_full(qf, dqf)

    def energy_of_full(self, qf: Array, dqf: Array) -> tuple[Array, Array]:
        """Kinetic and potential energy [J] of full coordinates (T, nbody) with no range checks."""
        layout, c = self.layout, self.constants
        qf, dqf = np.asarray(qf, dtype=float).T[:, None], np.asarray(dqf, dtype=float).T[:, None]
        ws = frames_of_full(layout, self.prepared, qf, dqf, np.zeros_like(qf))
        mb = layout.massive
        spare = (ws.c("energy arm", len(mb)), ws.c("energy spare", 3, len(mb)))
        com, velocity, _ = ws.points(mb, c.com[mb][:, :, None], ws.c("energy", 3, len(mb)), spare)
        mass, izz = c.mass[mb], c.izz[mb]  # (bodies, 1)
        kinetic = 0.5 * (mass * np.abs(velocity[:, 0]) ** 2 + izz * ws.omega[mb, 0] ** 2)
        potential = mass * layout.tree.gravity * com[:, 0].imag
        return kinetic.sum(axis=0), potential.sum(axis=0)

    def tcp_velocity(self, q: Any, dq: Any) -> Array:
        """Velocity of the TCP point in the world plane (T, 2) [m/s] (the power of a TCP force)."""
        q, dq, zero = joint_arrays(self.layout.tree, q, dq, np.zeros_like(np.atleast_2d(np.asarray(q, dtype=float))))
        ws = full_state(self.layout, self.prepared, q.T[:, None], dq.T[:, None], zero.T[:, None])
        b = self.layout.tree.tcp_body
        v = ws.motion[1, b, 0] + ws.factor[1, b, 0] * ws.rot[b, 0] * self.layout.tcp_point
        return np.stack([v.real, v.imag], axis=1)


def batched_inverse_dynamics(
    machine: Machine,
    designs: ArrayLike,
    position: ArrayLike,
    velocity: ArrayLike,
    acceleration: ArrayLike,
    tcp_force: ArrayLike | None = None,
    extras: SimulationExtras | None = None,
) -> tuple[Array, Array, Array, Array]:
    """Actuator forces [N], velocities, accelerations and strokes of D designs of one machine in one pass.

    The machine path's counterpart of :func:`hiab_sim.dynamics.analytic_batch.batched_inverse_dynamics`
    (e.g. the perturbed designs of a finite-difference gradient): design d gives what
    ``NewtonEulerInverseDynamics(machine, designs[d], extras)`` gives, to round-off.

    Args:
        machine: The machine.
        designs: Decision variable values (D, n_xi) in ``machine.decision_variables`` order; no
            bounds are checked (:func:`design_constants`).
        position: Independent joint samples (T, n) shared by every design, or (D, T, n).
        velocity: Their rates, same shape.
        acceleration: Their accelerations, same shape.
        tcp_force: Force of the environment on the TCP in the world plane [N], (2,), (T, 2) (the
            same for every design) or None.
        extras: Armature and damping per actuator, as :class:`NewtonEulerInverseDynamics`.

    Returns:
        Four arrays (D, T, n_chains): force, velocity, acceleration and stroke, in chain order.

    Raises:
        InvalidInputError: malformed designs, joint samples, tcp_force or extras (named field).

    """
    _check_extras(machine, extras)
    layout = layout_of(machine)
    c = design_constants(machine, layout, np.asarray(designs, dtype=float))
    D = c.designs
    joints = [np.asarray(x, dtype=float) for x in (position, velocity, acceleration)]
    if joints[0].ndim == 3:
        if joints[0].shape[0] != D or any(x.shape != joints[0].shape for x in joints):
            need = f"must be ({D}, T, n) like velocity and acceleration, or (T, n)"
            raise InvalidInputError("position", f"shape {joints[0].shape}", need)
        T = joints[0].shape[1]
        flat = joint_arrays(layout.tree, *(x.reshape(D * T, -1) for x in joints))
        q, dq, ddq = (x.reshape(D, T, -1).transpose(2, 0, 1) for x in flat)
    else:
        q, dq, ddq = (x.T[:, None] for x in joint_arrays(layout.tree, *joints))
    external = tcp_force_complex(tcp_force, q.shape[2])
    pc = prepare(layout, c)
    ws = full_state(layout, pc, q, dq, ddq)
    transmitted, _ = joint_forces(ws, pc, external)
    act = layout.actuated
    qf, dqf, ddqf = ws.q[act], ws.dq[act], ws.ddq[act]  # copies: the workspace is reused
    force = _with_extras(actuator_forces(ws, pc, transmitted).copy(), extras, dqf, ddqf)
    return tuple(np.ascontiguousarray(x.transpose(1, 2, 0)) for x in (force, dqf, ddqf, qf))  # type: ignore[return-value]


def _checked_design(machine: Machine, design: Sequence[float]) -> Array:
    """Design values (n_xi,) checked as :meth:`Machine.with_design` checks them: their number and bounds."""
    values = np.asarray(design, dtype=float).reshape(-1)
    variables = machine.decision_variables
    if values.shape != (len(variables),):
        raise InvalidInputError("design", f"{values.size} values", f"need {len(variables)}: {machine.variable_keys}")
    for v, value in zip(variables, values, strict=True):
        check_range(v.key, float(value), v.low, v.high, "m")
    return values


def _check_extras(machine: Machine, extras: SimulationExtras | None) -> None:
    if extras is not None and len(extras.armature_kg) != len(machine.chains):
        need = f"need one per actuator: {machine.actuator_names}"
        raise InvalidInputError("extras.armature_kg", f"{len(extras.armature_kg)} values", need)


def _with_extras(force: Array, extras: SimulationExtras | None, velocity: Array, acceleration: Array) -> Array:
    """The motor-side force f_x + (J_m k^2 + M_sm) a_x + b_f v_x, or f_x without extras [N]."""
    if extras is None:
        return force
    armature, damping = (
        np.asarray(x, dtype=float)[:, None, None] for x in (extras.armature_kg, extras.damping_Ns_per_m)
    )
    return force + armature * acceleration + damping * velocity

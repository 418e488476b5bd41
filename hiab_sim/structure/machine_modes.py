"""Natural frequencies of any machine file on its drive trains' axial stiffness, from its inverse dynamics.

The model is :mod:`hiab_sim.structure.natural_frequency`'s (locked rotors, each drive train a spring
k_a(x_a) between its pins, THK's series formula :func:`hiab_sim.emla.drive_stiffness.axial_stiffness`),
written for a machine description through nothing but an inverse-dynamics path f(q, dq, ddq, F_tcp)
(Newton-Euler or MuJoCo, :func:`hiab_sim.machine.dynamics.paths.make_machine_dynamics`):

* actuator Jacobian: the actuator rates are linear in the joint rates, v_x = J_x dq, so column i of
  J_x is the ID's actuator velocity at dq = e_i;
* mass matrix: with every independent joint driven by one actuator, virtual power gives the joint
  forces tau = J_x^T f, and M(q) ddq = tau - g(q) at dq = 0, so column i of M is
  J_x^T (f(q, 0, e_i) - f(q, 0, 0)) (the ID is affine in ddq); symmetrised. A payload of mass m
  held rigidly at the TCP adds m J_tcp^T J_tcp (J_tcp: the TCP's in-plane acceleration per unit ddq
  at rest, :class:`hiab_sim.machine.kinematics.tracked.TrackedKinematics`);
* stiffness: K = J_x^T diag(k) J_x + J_x^T df_s/dq, the second term the load's geometric stiffness
  (f_s the static actuator forces, central differences, symmetrised), as in the crane's module;
* K phi = omega^2 M phi (:func:`hiab_sim.structure.natural_frequency.generalized_eigh`).

A small-amplitude free vibration of the spring-mounted MuJoCo model
(:mod:`hiab_sim.structure.machine_free_vibration`) is the independent check.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_range
from hiab_sim.emla.drive_stiffness import axial_stiffness
from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.paths import MachineInverseDynamics
from hiab_sim.machine.kinematics.tracked import TrackedKinematics
from hiab_sim.structure.natural_frequency import GEOMETRIC_STEP, Modes, differenced_stiffness, generalized_eigh

#: Inset of the working-range grid from the ranges' ends [rad or m]: ten central-difference steps.
GRID_INSET = 10.0 * GEOMETRIC_STEP


def _force(inverse: MachineInverseDynamics, q: Array, dq: Array, ddq: Array, tcp_force: Array | None) -> Array:
    return np.asarray(inverse(q, dq, ddq, tcp_force=tcp_force).force, dtype=float)


def actuator_jacobian(inverse: MachineInverseDynamics, position: ArrayLike) -> Array:
    """J_x = dx/dq (T, n_a, n) at static poses: the actuator velocities for unit joint rates."""
    q = np.atleast_2d(np.asarray(position, dtype=float))
    _T, n = q.shape
    zero = np.zeros_like(q)
    columns = []
    for i in range(n):
        rate = np.zeros_like(q)
        rate[:, i] = 1.0
        columns.append(np.asarray(inverse(q, rate, zero).velocity, dtype=float))
    return np.stack(columns, axis=-1)


def static_forces(inverse: MachineInverseDynamics, position: ArrayLike, tcp_force: ArrayLike | None = None) -> Array:
    """Actuator forces holding static poses (T, n_a) [N]; ``tcp_force`` (2,) or (T, 2) in the world plane."""
    q = np.atleast_2d(np.asarray(position, dtype=float))
    zero = np.zeros_like(q)
    return _force(inverse, q, zero, zero, None if tcp_force is None else np.asarray(tcp_force, dtype=float))


def mass_matrix(
    inverse: MachineInverseDynamics,
    position: ArrayLike,
    jacobian: Array,
    payload_kg: float = 0.0,
    kinematics: TrackedKinematics | None = None,
) -> Array:
    """Joint-space mass matrix M (T, n, n) [kg, kg m, kg m^2] (module docstring); ``kinematics`` for a payload."""
    q = np.atleast_2d(np.asarray(position, dtype=float))
    T, n = q.shape
    zero = np.zeros_like(q)
    rest = _force(inverse, q, zero, zero, None)
    M = np.zeros((T, n, n))
    tcp = np.zeros((T, 2, n))
    for i in range(n):
        unit = np.zeros_like(q)
        unit[:, i] = 1.0
        M[:, :, i] = np.einsum("tai,ta->ti", jacobian, _force(inverse, q, zero, unit, None) - rest)
        if payload_kg > 0.0:
            if kinematics is None:
                raise InvalidInputError("kinematics", None, "a payload's inertia needs the TCP kinematics")
            tcp[:, :, i] = kinematics.samples(q, zero, unit).acceleration[:, :2]
    M += payload_kg * np.einsum("tki,tkj->tij", tcp, tcp)
    return 0.5 * (M + np.swapaxes(M, 1, 2))


def geometric_stiffness(
    inverse: MachineInverseDynamics, position: ArrayLike, jacobian: Array, tcp_force: ArrayLike | None = None
) -> Array:
    """J_x^T df_s/dq of the static actuator forces, symmetrised (T, n, n) [N m per unit joint]."""
    return differenced_stiffness(lambda q: static_forces(inverse, q, tcp_force), position, jacobian)


def drive_stiffness(emlas: EmlaSet, names: Sequence[str], stroke: Array) -> Array:
    """Each drive train's axial stiffness k (T, n_a) [N/m] at the strokes (T, n_a) [m], actuators by name."""
    by_name = {p.name: p for p in emlas}
    missing = [name for name in names if name not in by_name]
    if missing:
        raise InvalidInputError(
            "emla", missing, f"the EMLA file has no actuator of these names; it has {list(by_name)}"
        )
    return np.stack([axial_stiffness(by_name[name], stroke[:, k]) for k, name in enumerate(names)], axis=1)


def machine_natural_frequencies(
    machine: Machine,
    inverse: MachineInverseDynamics,
    emlas: EmlaSet,
    position: ArrayLike,
    tcp_force: ArrayLike | None = None,
    payload_kg: float = 0.0,
    mass: Array | None = None,
    tracked: Sequence[str] | None = None,
) -> Modes:
    """Locked-rotor natural frequencies and mode shapes of a machine at static poses (T, n) (module docstring).

    Args:
        machine: The machine at the design ``inverse`` was built for (its TCP kinematics for a payload).
        inverse: One of the machine's inverse-dynamics paths at that design (bare mechanism).
        emlas: EMLA set with ``screw`` and ``drive_stiffness`` data for every actuator (its EMLA name).
        position: Joint samples (T, n) [rad, m] in ``machine.joint_names`` order.
        tcp_force: Force of the environment on the TCP in the world plane [N], (2,) or (T, 2), or None.
        payload_kg: Mass held rigidly at the TCP [kg] (its inertia; its weight belongs in ``tcp_force``).
        mass: Optional mass matrix (T, n, n) from another path (to compare paths).
        tracked: The tracked coordinates beyond the TCP's x, y of the study (n - 2 names; default
            ``tcp_angle`` for a three-joint machine): the TCP kinematics a payload's inertia needs.

    """
    q = np.atleast_2d(np.asarray(position, dtype=float))
    check_range("payload_kg", payload_kg, 0.0, unit="kg")
    force = None if tcp_force is None else np.asarray(tcp_force, dtype=float)
    jx = actuator_jacobian(inverse, q)
    extra = list(tracked) if tracked is not None else ["tcp_angle"] * (len(machine.joint_names) - 2)
    kin = TrackedKinematics(machine, extra) if payload_kg > 0.0 else None
    M = mass_matrix(inverse, q, jx, payload_kg, kin) if mass is None else np.asarray(mass, dtype=float)
    zero = np.zeros_like(q)
    rest = inverse(q, zero, zero, tcp_force=force)
    emla_of = {c.name: c.actuator.emla or c.name for c in machine.chains}
    names = tuple(emla_of[name] for name in rest.names)  # the samples' chains by their EMLAs
    k = drive_stiffness(emlas, names, np.asarray(rest.stroke, dtype=float))
    K = np.einsum("tai,ta,taj->tij", jx, k, jx) + geometric_stiffness(inverse, q, jx, force)
    w2, shape = generalized_eigh(K, M)
    if np.any(w2 <= 0.0):
        raise InvalidInputError("stiffness", f"omega^2 = {w2.min():.3g}", "every pose must be stable (K > 0)")
    freq = np.sqrt(w2) / (2.0 * math.pi)
    return Modes(freq, shape, np.einsum("tai,tij->taj", jx, shape), k, names)


def machine_working_range_poses(machine: Machine, per_joint: int = 7) -> Array:
    """A grid of static poses (N, n) over every independent joint's working range, ``per_joint`` values each.

    The grid's ends lie :data:`GRID_INSET` inside the range, so that the geometric stiffness's
    central differences stay in the range the inverse dynamics accepts.
    """
    if isinstance(per_joint, bool) or int(per_joint) != per_joint or per_joint < 1:
        raise InvalidInputError("per_joint", per_joint, "must be a positive whole number")
    axes = []
    for name in machine.joint_names:
        low, high = machine.joint_link(name).joint_range  # type: ignore[misc]  # a joint's link has its range
        lo, hi = float(low) + GRID_INSET, float(high) - GRID_INSET
        axes.append(np.linspace(lo, hi, int(per_joint)) if per_joint > 1 else np.array([0.5 * (lo + hi)]))
    return np.stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")], axis=1)

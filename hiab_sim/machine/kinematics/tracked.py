"""Tracked coordinates of a machine's TCP, their time derivatives and exact partials; inverse kinematics.

The study's tracking constraints (``const_b``..``const_d`` of the paper) prescribe r(t), its rate
and its acceleration. For any machine of :mod:`hiab_sim.machine.description` the tracked
coordinates are r = (x_tcp, y_tcp, *extra): the TCP point in the world plane [m] and n - 2 more,
each either a joint coordinate (r_i = q_j [rad or m]) or ``tcp_angle``, the absolute angle of the
TCP frame's x axis in the world plane [rad]. With n joints and n tracked coordinates the inverse
kinematics is square.

Planar chain in complex form
----------------------------
Every revolute joint turns about the plane normal, so the world rotation of a link is
``R_k = Rz(S_k) F_k``, with ``S_k`` the sum of the revolute coordinates from the root to k and
``F_k`` its rotation at zero joints (:meth:`Machine.fixed_rotations`; exact when each revolute joint
frame's world z axis is the plane normal, as the description checks). The path root -> TCP link
then adds one segment per link and one for the TCP, and the TCP point is, in x + i y,

    p = P0 + sum_m E_m W_m,   E_m = exp(i A_m . q),   W_m = c_m + (B_m . q) u_m,

with ``A_m`` the 0/1 selection of the revolute joints above segment m (its parent), ``c_m`` the
joint frame's (or the TCP's) offset ``F_parent p_joint`` in the plane, ``u_m`` the world direction
``F_k e_x`` of a prismatic joint at zero angles and ``B_m`` the selection of that joint (zero for a
revolute one). Time derivatives (omega_m = A_m . dq, alpha_m = A_m . ddq):

    v = sum_m E_m (i omega_m W_m + dW_m)
    a = sum_m E_m ((i alpha_m - omega_m^2) W_m + 2 i omega_m dW_m + ddW_m)

whose partials with respect to (q, dq, ddq) are written out in :meth:`TrackedKinematics.samples`.
The TCP angle is ``angle0 + A_tcp . q`` (not wrapped: continuous along a trajectory, equal to the
world angle modulo 2 pi), with ``angle0`` in (-pi, pi] the angle at zero joints. The TCP's
out-of-plane coordinate is the sum of the constant z offsets (``z``), plus a prismatic joint's z
rate (zero to the description's planarity tolerance).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import PLANAR_TOLERANCE, Link, Machine

CArray = NDArray[np.complex128]

#: The tracked coordinate that is the TCP frame's absolute angle in the plane [rad].
TCP_ANGLE = "tcp_angle"
#: Names of the two tracked coordinates of the TCP point [m].
POINT_NAMES = ("x_tcp", "y_tcp")
#: |det J| below which inverse kinematics calls a pose singular (units of the TCP point rows squared,
#: m^2 per unit of the joint columns): the value of :func:`hiab_sim.study.motion.trajectory.inverse_kinematics`.
SINGULAR_DET = 1e-9
#: Newton steps per sample before a target counts as out of reach (as the crane's inverse kinematics).
NEWTON_ITERATIONS = 50
#: Largest Newton step per joint coordinate [rad or m] (as the crane's inverse kinematics).
STEP_CLIP = 0.2


@dataclass(frozen=True)
class TrackedSamples:
    """Tracked coordinates r and their time derivatives, each (T, n_r) [m, rad or m per s^k].

    ``d_position``, ``d_velocity``, ``d_acceleration``: partials with respect to the joint samples,
    (T, n_r, 3 n): columns 0..n-1 d/dq, n..2n-1 d/d(dq), 2n..3n-1 d/d(ddq), joints in
    :attr:`Machine.joint_names` order.
    """

    position: Array
    velocity: Array
    acceleration: Array
    d_position: Array
    d_velocity: Array
    d_acceleration: Array

    def __post_init__(self) -> None:
        shape = np.shape(self.position)
        if len(shape) != 2:
            raise InvalidInputError("samples.position", f"shape {shape}", "must be (T, n_r)")
        for name in ("velocity", "acceleration"):
            got = np.shape(getattr(self, name))
            if got != shape:
                raise InvalidInputError(f"samples.{name}", f"shape {got}", f"must be {shape} like position")
        partial = np.shape(self.d_position)
        if len(partial) != 3 or partial[:2] != shape or partial[2] % 3:
            raise InvalidInputError("samples.d_position", f"shape {partial}", f"must be ({shape[0]}, {shape[1]}, 3 n)")
        for name in ("d_velocity", "d_acceleration"):
            got = np.shape(getattr(self, name))
            if got != partial:
                raise InvalidInputError(f"samples.{name}", f"shape {got}", f"must be {partial} like d_position")


class TrackedKinematics:
    """Tracked coordinates r = (x_tcp, y_tcp, *extra) of a machine's TCP (see the module docstring).

    Args:
        machine: The machine; its TCP is ``machine.tcp`` on ``machine.tcp_link``.
        extra: n - 2 names, each a joint of ``machine.joint_names`` or ``tcp_angle``, no repeats.

    Attributes:
        machine: The machine.
        names: Names of the tracked coordinates, e.g. ("x_tcp", "y_tcp", "xt2").
        n: Number of joints (= tracked coordinates).
        z: The TCP's out-of-plane coordinate in the world [m] (constant: the chain is planar).
        extra_joints: Per extra coordinate, its joint's index in ``machine.joint_names`` (None: tcp_angle).
        P0, A, B, c, u: The chain's constants of the module docstring: root point [m] (complex),
            revolute and prismatic selections (M, n), offsets [m] and prismatic directions (M,).
        angle0: TCP angle at zero joints [rad]; angle_rate: d(tcp_angle)/dq (n,).
        z_rate: dz/dq of the TCP (n,) [1] (a prismatic axis's out-of-plane component, ~0).

    Raises:
        InvalidInputError: (field ``tracked``) an unknown or repeated name, the wrong count, a
            joint off the TCP's path left untracked; (field ``tcp.R``) ``tcp_angle`` asked for
            with the TCP's x axis out of the plane.

    """

    def __init__(self, machine: Machine, extra: Sequence[str]) -> None:
        joints = machine.joint_names
        self.machine = machine
        self.n = len(joints)
        self.names = POINT_NAMES + tuple(self._check_extra(machine, extra))
        rotations = machine.fixed_rotations()
        path = _path_to_tcp(machine)
        root = path[0]
        p0 = np.asarray(root.joint_frame.position, dtype=float)
        self.P0 = complex(p0[0], p0[1])
        z = float(p0[2])
        above = np.zeros(self.n)  # revolute joints above the current link
        a_rows: list[Array] = []
        b_rows: list[Array] = []
        c: list[complex] = []
        u: list[complex] = []
        self.z_rate = np.zeros(self.n)  # dz/dq of the TCP (prismatic axes out of the plane, ~0)
        for link in path[1:]:
            fp = rotations[str(link.parent)]
            offset = fp @ np.asarray(link.joint_frame.position, dtype=float)
            j = joints.index(link.joint)
            b = np.zeros(self.n)
            direction = np.zeros(3)
            if link.joint_kind == "prismatic":
                b[j] = 1.0
                direction = rotations[link.name][:, 0]
                self.z_rate[j] = direction[2]
            a_rows.append(above.copy())
            b_rows.append(b)
            c.append(complex(offset[0], offset[1]))
            u.append(complex(direction[0], direction[1]))
            z += float(offset[2])
            if link.joint_kind == "revolute":
                above[j] = 1.0
        tcp = rotations[machine.tcp_link] @ np.asarray(machine.tcp.position, dtype=float)
        a_rows.append(above.copy())
        b_rows.append(np.zeros(self.n))
        c.append(complex(tcp[0], tcp[1]))
        u.append(0j)
        self.z = z + float(tcp[2])
        self.A, self.B = np.array(a_rows), np.array(b_rows)  # (M, n) selections
        self.c, self.u = np.array(c, dtype=complex), np.array(u, dtype=complex)  # (M,) [m], [1]
        self.angle_rate = above  # d(tcp_angle)/dq
        axis = rotations[machine.tcp_link] @ np.asarray(machine.tcp.rotation, dtype=float)[:, 0]
        if TCP_ANGLE in self.names and abs(axis[2]) > PLANAR_TOLERANCE:
            raise InvalidInputError("tcp.R", f"x axis {axis.round(6).tolist()}", "tcp_angle needs it in the plane")
        self.angle0 = math.atan2(axis[1], axis[0])
        self.extra_joints: tuple[int | None, ...] = tuple(
            None if name == TCP_ANGLE else joints.index(name) for name in self.names[2:]
        )

    @staticmethod
    def _check_extra(machine: Machine, extra: Sequence[str]) -> list[str]:
        joints = machine.joint_names
        allowed = f"n - 2 = {len(joints) - 2} distinct names of {[*joints, TCP_ANGLE]}"
        if isinstance(extra, str):
            raise InvalidInputError("tracked", extra, f"must be a list of {allowed}")
        names = [str(name) for name in extra]
        if len(names) != len(joints) - 2 or len(set(names)) != len(names):
            raise InvalidInputError("tracked", str(names), f"must be {allowed}")
        for name in names:
            if name != TCP_ANGLE and name not in joints:
                raise InvalidInputError("tracked", name, f"unknown; must be {allowed}")
        on_path = {link.joint for link in _path_to_tcp(machine)[1:]}
        loose = [j for j in joints if j not in on_path and j not in names]
        if loose:
            raise InvalidInputError("tracked", str(names), f"joints {loose} do not move the TCP: track them")
        return names

    def _check_joints(self, name: str, values: ArrayLike) -> Array:
        a = np.atleast_2d(np.asarray(values, dtype=float))
        if a.ndim != 2 or a.shape[1] != self.n:
            raise InvalidInputError(name, f"shape {np.shape(values)}", f"must be (T, {self.n})")
        return a

    def position(self, q: ArrayLike) -> Array:
        """TCP (x, y, z) in the world for joint samples q (T, n) [m]."""
        qa = self._check_joints("joints", q)
        e = np.exp(1j * (qa @ self.A.T))
        p = self.P0 + np.sum(e * (self.c + (qa @ self.B.T) * self.u), axis=1)
        return np.column_stack([p.real, p.imag, self.z + qa @ self.z_rate])

    def samples(self, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike) -> TrackedSamples:
        """Tracked coordinates, their first two time derivatives and exact partials.

        Args:
            q: Joint positions (T, n) [rad or m].
            dq: Joint velocities (T, n) [rad/s or m/s].
            ddq: Joint accelerations (T, n) [rad/s^2 or m/s^2].

        Returns:
            :class:`TrackedSamples` with r [m, rad], dr/dt, d^2r/dt^2 and their partials.

        """
        qa, dqa, ddqa = (self._check_joints(n, v) for n, v in (("q", q), ("dq", dq), ("ddq", ddq)))
        if not qa.shape == dqa.shape == ddqa.shape:
            raise InvalidInputError("dq", f"shapes {qa.shape}, {dqa.shape}, {ddqa.shape}", "q, dq, ddq must agree")
        A, B, u = self.A, self.B, self.u
        E = np.exp(1j * (qa @ A.T))  # (T, M)
        W = self.c + (qa @ B.T) * u
        dW, ddW = (dqa @ B.T) * u, (ddqa @ B.T) * u
        w, al = dqa @ A.T, ddqa @ A.T  # segment angular rates [rad/s], accelerations [rad/s^2]
        rate = 1j * w * W + dW
        acc = (1j * al - w**2) * W + 2j * w * dW + ddW
        p = self.P0 + np.sum(E * W, axis=1)
        v = np.sum(E * rate, axis=1)
        a = np.sum(E * acc, axis=1)
        Eu = E * u
        # complex partials (T, n) of p, v, a with respect to q, dq, ddq (chain rule on the sums above)
        dp_q = (1j * E * W) @ A + Eu @ B
        dv_q = (1j * E * rate) @ A + (1j * w * Eu) @ B
        da_q = (1j * E * acc) @ A + ((1j * al - w**2) * Eu) @ B
        da_dq = (E * (-2.0 * w * W + 2j * dW)) @ A + (2j * w * Eu) @ B
        zero = np.zeros_like(dp_q)
        n_t = len(qa)
        out = {key: np.zeros((n_t, self.n)) for key in ("r", "dr", "ddr")}
        parts = {key: np.zeros((n_t, self.n, 3 * self.n)) for key in ("r", "dr", "ddr")}
        point = {
            "r": (p, (dp_q, zero, zero)),
            "dr": (v, (dv_q, dp_q, zero)),
            "ddr": (a, (da_q, da_dq, dp_q)),
        }
        for key, (value, blocks) in point.items():
            out[key][:, 0], out[key][:, 1] = value.real, value.imag
            full = np.concatenate(blocks, axis=1)
            parts[key][:, 0], parts[key][:, 1] = full.real, full.imag
        for row, joint in enumerate(self.extra_joints, start=2):
            for slot, (key, values) in enumerate((("r", qa), ("dr", dqa), ("ddr", ddqa))):
                if joint is None:  # tcp_angle = angle0 + A_tcp . q, linear in q
                    out[key][:, row] = values @ self.angle_rate
                    parts[key][:, row, slot * self.n : (slot + 1) * self.n] = self.angle_rate
                else:  # r = q_joint
                    out[key][:, row] = values[:, joint]
                    parts[key][:, row, slot * self.n + joint] = 1.0
            if joint is None:
                out["r"][:, row] += self.angle0
        return TrackedSamples(out["r"], out["dr"], out["ddr"], parts["r"], parts["dr"], parts["ddr"])


def _path_to_tcp(machine: Machine) -> list[Link]:
    """Links from the root to the TCP link, root first."""
    path = [machine.link(machine.tcp_link)]
    while path[-1].parent is not None:
        path.append(machine.link(path[-1].parent))
    return path[::-1]


def inverse_kinematics(
    kin: TrackedKinematics,
    position: ArrayLike,
    velocity: ArrayLike,
    acceleration: ArrayLike,
    guess: ArrayLike,
    tol: float = 1e-12,
) -> tuple[Array, Array, Array]:
    """Joint samples (q, dq, ddq), each (T, n), that put the tracked coordinates on a reference.

    Newton steps on r(q) = r_ref sample by sample with continuation: the first sample starts at
    ``guess`` (n,), every later one at the previous solution (the start's branch, e.g. its elbow,
    is kept); each step is clipped to ``STEP_CLIP`` per coordinate and a tracked joint starts at
    its prescribed value. Rates solve J dq = v_ref and J ddq = a_ref - (terms in dq) exactly, with
    J = dr/dq: r's rate and acceleration are linear in dq and ddq with that matrix (the same
    scheme as the crane's :func:`hiab_sim.study.motion.trajectory.inverse_kinematics`).

    Args:
        kin: The tracked kinematics.
        position: Reference r (T, n) [m, rad].
        velocity: dr/dt (T, n) [m/s, rad/s].
        acceleration: d^2r/dt^2 (T, n) [m/s^2, rad/s^2].
        guess: Joint coordinates to start the first sample from (n,) [rad or m].
        tol: Largest residual |r(q) - r_ref| accepted [m or rad].

    Raises:
        InvalidInputError: (field ``reference``) a sample out of reach (Newton did not converge)
            or at a singular pose (|det J| < ``SINGULAR_DET``), naming its index and point;
            (fields ``reference``, ``guess``) arrays of the wrong shape.

    """
    n = kin.n
    ref = [np.atleast_2d(np.asarray(a, dtype=float)) for a in (position, velocity, acceleration)]
    if any(a.ndim != 2 or a.shape != (len(ref[0]), n) for a in ref):
        raise InvalidInputError("reference", f"shapes {[a.shape for a in ref]}", f"must all be (T, {n})")
    start = np.asarray(guess, dtype=float)
    if start.shape != (n,):
        raise InvalidInputError("guess", f"shape {start.shape}", f"must be ({n},)")
    n_t = len(ref[0])
    q = np.zeros((n_t, n))
    current = start.copy()
    rest = np.zeros((1, n))
    prescribed = [(row, joint) for row, joint in enumerate(kin.extra_joints, start=2) if joint is not None]
    for i in range(n_t):
        target = ref[0][i]
        for row, joint in prescribed:
            current[joint] = target[row]
        for _ in range(NEWTON_ITERATIONS):
            s = kin.samples(current[None, :], rest, rest)
            residual = s.position[0] - target
            if np.max(np.abs(residual)) < tol:
                break
            jac = s.d_position[0, :, :n]
            if abs(np.linalg.det(jac)) < SINGULAR_DET:
                raise InvalidInputError("reference", _point(kin, i, target), "must not be a singular pose")
            current = current - np.clip(np.linalg.solve(jac, residual), -STEP_CLIP, STEP_CLIP)
        else:
            raise InvalidInputError(
                "reference", _point(kin, i, target), "must be within reach (the inverse kinematics did not converge)"
            )
        q[i] = current
    zero = np.zeros((n_t, n))
    s0 = kin.samples(q, zero, zero)
    jac = s0.d_velocity[:, :, n : 2 * n]  # = dr/dq
    singular = np.flatnonzero(np.abs(np.linalg.det(jac)) < SINGULAR_DET)
    if singular.size:
        i = int(singular[0])
        raise InvalidInputError("reference", _point(kin, i, ref[0][i]), "must not be a singular pose")
    dq = np.asarray(np.linalg.solve(jac, ref[1][..., None])[..., 0], dtype=float)
    s1 = kin.samples(q, dq, zero)
    ddq = np.asarray(np.linalg.solve(jac, (ref[2] - s1.acceleration)[..., None])[..., 0], dtype=float)
    return q, dq, ddq


def _point(kin: TrackedKinematics, index: int, target: Array) -> str:
    values = ", ".join(f"{name} = {value:.6g}" for name, value in zip(kin.names, target, strict=True))
    return f"sample {index}: ({values})"

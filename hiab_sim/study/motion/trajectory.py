"""B-spline joint trajectories, the reference samples, planar TCP kinematics and inverse kinematics.

* :class:`SplineBasis`: theta(t, c) = B(t) c and its time derivatives (eqs. ``matrix_basis``,
  ``matrix_basis_d``, ``matrix_basis_dd``) with scipy's B-splines (clamped uniform knots).
* :class:`TcpKinematics`: the TCP's position, velocity and acceleration in the vertical plane of
  {W} (x, y; y up) and their exact partials with respect to (theta, dtheta, ddtheta). They enter
  the tracking constraints ``const_b``..``const_d``; J and dJ of the seed are implicit in them.
* :class:`Reference` and :func:`timing_law`: what every reference kind samples
  (the kinds themselves, the spiral among them, are :mod:`hiab_sim.study.references.kinds`).
* :func:`inverse_kinematics` and :func:`fit_coefficients`: the initial spline coefficients.

The TCP does not depend on the link lengths Xi (the boom hinges are fixed), so nothing here does.
Tracked coordinates are r = (x_tcp, y_tcp, xt2): the crane's three joints are redundant for a
planar TCP point, and the study prescribes the telescope as the third reference coordinate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BSpline

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.kinematics.tracked import TrackedSamples


class SplineBasis:
    """Clamped B-spline basis of ``n`` control points and degree ``k`` on [0, duration].

    The knot vector repeats 0 and ``duration`` k + 1 times and spaces n - k - 1 interior knots
    uniformly, so theta(0) = c_0, theta(T) = c_{n-1}; rest at both ends is a linear condition.
    """

    def __init__(self, n: int, k: int, duration: float) -> None:
        if k < 3 or n < k + 2:
            raise InvalidInputError("spline", f"n={n}, k={k}", "need degree k >= 3 and n >= k + 2")
        self.n, self.k, self.duration = n, k, duration
        interior = np.linspace(0.0, duration, n - k + 1)[1:-1]
        self.knots = np.concatenate([np.zeros(k + 1), interior, np.full(k + 1, duration)])
        self._spline = BSpline(self.knots, np.eye(n), k, extrapolate=False)

    def matrix(self, times: Array, nu: int = 0) -> Array:
        """Basis matrix d^nu B / dt^nu at ``times``: shape (T, n) (one joint's row block of B(t))."""
        t = np.clip(np.asarray(times, dtype=float), 0.0, self.duration)
        if nu == 0:
            # The sparse design matrix and the vector-valued spline agree; keep the documented API.
            return np.asarray(BSpline.design_matrix(t, self.knots, self.k).toarray())
        return np.asarray(self._spline(t, nu=nu))

    def matrices(self, times: Array) -> tuple[Array, Array, Array]:
        """(B, dB/dt, d^2B/dt^2) at ``times``, each (T, n)."""
        return self.matrix(times, 0), self.matrix(times, 1), self.matrix(times, 2)


@dataclass(frozen=True)
class JointTrajectory:
    """q, dq, ddq at sample times, each (T, n) for the machine's joints (the crane's theta1, theta2, xt2)."""

    time: Array
    position: Array
    velocity: Array
    acceleration: Array


def evaluate(basis: SplineBasis, coefficients: Array, times: Array) -> JointTrajectory:
    """Joint samples from coefficients c of shape (n_joints, n) (eqs. ``matrix_basis``..``_dd``)."""
    c = np.asarray(coefficients, dtype=float).reshape(-1, basis.n)
    B, dB, ddB = basis.matrices(times)
    return JointTrajectory(np.asarray(times, dtype=float), B @ c.T, dB @ c.T, ddB @ c.T)


# ---------------------------------------------------------------------------------------------
# TCP kinematics in the plane
# ---------------------------------------------------------------------------------------------


#: Tracked coordinates r, their time derivatives and partials w.r.t. q9 (the crane's r = (x_tcp, y_tcp, xt2):
#: each (T, 3), partials (T, 3, 9), columns 0-2 d/dtheta, 3-5 d/ddtheta, 6-8 d/dddtheta); the one samples
#: type of every machine's tracked kinematics (:mod:`hiab_sim.machine.kinematics.tracked`).
TcpSamples = TrackedSamples


class TcpKinematics:
    """Planar TCP kinematics p = H1 + e^{i phi1} H2 + e^{i (phi1 + phi2)} (A + xt2 U) in complex form.

    phi_j = alpha_j + theta_j - joint_offset_j is the boom rotation; H1 is the lift hinge in
    {W}, H2 the tilt hinge in the lift boom frame, A + xt2 U the TCP in the tilt boom frame.
    Every rotation of the chain is about z, so the TCP's z is constant (``z``).
    """

    def __init__(self, crane: Crane) -> None:
        tele = crane.telescope
        rot = np.asarray(tele.cylinder_frame.rotation)
        tcp_local = np.asarray(crane.tcp_in_telescope_rod.position)
        a = np.asarray(tele.cylinder_frame.position) + rot @ (np.array([tele.rod_offset, 0.0, 0.0]) + tcp_local)
        u = rot[:, 0]
        h1, h2 = crane.lift.boom_hinge, crane.tilt.boom_hinge
        self.H1, self.H2 = complex(h1[0], h1[1]), complex(h2[0], h2[1])
        self.A, self.U = complex(a[0], a[1]), complex(u[0], u[1])
        self.offsets = (
            crane.lift.base_axis_angle - crane.lift.joint_offset,
            crane.tilt.base_axis_angle - crane.tilt.joint_offset,
        )
        self.z = float(h1[2] + h2[2] + a[2])
        self.z_rate = float(u[2])  # 0 for the XS 031: xt2 does not move the TCP out of the plane

    def position(self, joints: Array) -> Array:
        """TCP (x, y, z) in {W} for joint positions (T, 3) [m]."""
        q = np.atleast_2d(joints)
        e1 = np.exp(1j * (q[:, 0] + self.offsets[0]))
        e12 = e1 * np.exp(1j * (q[:, 1] + self.offsets[1]))
        p = self.H1 + e1 * self.H2 + e12 * (self.A + q[:, 2] * self.U)
        return np.column_stack([p.real, p.imag, self.z + self.z_rate * q[:, 2]])

    def samples(self, position: Array, velocity: Array, acceleration: Array) -> TcpSamples:
        """Tracked coordinates, their rates and exact partials (see :class:`TcpSamples`)."""
        th, dth, ddth = (np.atleast_2d(a) for a in (position, velocity, acceleration))
        e1 = np.exp(1j * (th[:, 0] + self.offsets[0]))
        e12 = e1 * np.exp(1j * (th[:, 1] + self.offsets[1]))
        w1, w12 = dth[:, 0], dth[:, 0] + dth[:, 1]
        a1, a12 = ddth[:, 0], ddth[:, 0] + ddth[:, 1]
        xt, dxt, ddxt = th[:, 2], dth[:, 2], ddth[:, 2]
        Q = self.A + xt * self.U
        P1, P12 = e1 * self.H2, e12 * Q
        EU = e12 * self.U
        p = self.H1 + P1 + P12
        V1 = 1j * w1 * P1
        V12 = e12 * (1j * w12 * Q + dxt * self.U)
        A1 = (1j * a1 - w1**2) * P1
        A12 = e12 * ((1j * a12 - w12**2) * Q + (2j * w12 * dxt + ddxt) * self.U)
        zero = np.zeros_like(p)
        one = np.ones_like(xt)
        # complex partials of p, v, a (planar part) w.r.t. the 9 joint inputs
        dp = [1j * (P1 + P12), 1j * P12, EU, zero, zero, zero, zero, zero, zero]
        dv = [
            1j * (V1 + V12),
            1j * V12,
            1j * w12 * EU,
            1j * (P1 + P12),
            1j * P12,
            EU,
            zero,
            zero,
            zero,
        ]
        dw = -2.0 * w12 * P12 + 2j * dxt * EU
        da = [
            1j * (A1 + A12),
            1j * A12,
            (1j * a12 - w12**2) * EU,
            -2.0 * w1 * P1 + dw,
            dw,
            2j * w12 * EU,
            1j * (P1 + P12),
            1j * P12,
            EU,
        ]

        def stack(value: np.ndarray, x3: Array) -> Array:
            return np.column_stack([value.real, value.imag, x3])

        def partials(columns: list[np.ndarray], slot: int) -> Array:
            out = np.zeros((len(xt), 3, 9))
            for j, col in enumerate(columns):
                out[:, 0, j], out[:, 1, j] = col.real, col.imag
            out[:, 2, slot] = one
            return out

        return TcpSamples(
            position=stack(p, xt),
            velocity=stack(V1 + V12, dxt),
            acceleration=stack(A1 + A12, ddxt),
            d_position=partials(dp, 2),
            d_velocity=partials(dv, 5),
            d_acceleration=partials(da, 8),
        )


# ---------------------------------------------------------------------------------------------
# Reference samples
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Reference:
    """Reference r(t) = (x_tcp, y_tcp, xt2) and its rates at sample times, each (T, 3); TCP z [m]."""

    time: Array
    position: Array
    velocity: Array
    acceleration: Array
    z: float
    centre: tuple[float, float]

    def tcp(self) -> Array:
        """Reference TCP points (T, 3) in {W} (x, y, z)."""
        return np.column_stack([self.position[:, :2], np.full(len(self.time), self.z)])


def timing_law(times: Array, duration: float) -> tuple[Array, Array, Array]:
    """Rest-to-rest quintic s = 10 tau^3 - 15 tau^4 + 6 tau^5 and its first two time derivatives."""
    tau = np.clip(np.asarray(times, dtype=float) / duration, 0.0, 1.0)
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    ds = 30.0 * tau**2 * (1.0 - tau) ** 2 / duration
    dds = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / duration**2
    return s, ds, dds


# ---------------------------------------------------------------------------------------------
# Inverse kinematics and the initial coefficients
# ---------------------------------------------------------------------------------------------


def inverse_kinematics(
    kin: TcpKinematics, reference: Reference, guess: tuple[float, float], tol: float = 1e-12
) -> JointTrajectory:
    """Joint samples that put the TCP on the reference, by Newton steps with continuation.

    The telescope is prescribed (third reference coordinate); theta1, theta2 follow from the
    2x2 planar problem, started at ``guess`` for the first sample and at the previous solution
    afterwards (the elbow branch of the start is kept). Velocities and accelerations solve
    J dtheta = v_r and J ddtheta = a_r - (terms in dtheta) exactly.

    Raises:
        InvalidInputError: ``reference`` is not reachable (Newton fails or J is singular).

    """
    n = len(reference.time)
    theta = np.zeros((n, 3))
    theta[:, 2] = reference.position[:, 2]
    current = np.array(guess, dtype=float)
    for i in range(n):
        target = reference.position[i, :2]
        for _ in range(50):
            joints = np.array([[current[0], current[1], theta[i, 2]]])
            s = kin.samples(joints, np.zeros((1, 3)), np.zeros((1, 3)))
            residual = s.position[0, :2] - target
            if np.max(np.abs(residual)) < tol:
                break
            jac = s.d_position[0, :2, :2]
            if abs(np.linalg.det(jac)) < 1e-9:
                raise InvalidInputError(
                    "reference", f"t = {reference.time[i]:.4g} s", "reaches a singular pose of the booms"
                )
            step = np.linalg.solve(jac, residual)
            current = current - np.clip(step, -0.2, 0.2)
        else:
            raise InvalidInputError(
                "reference",
                f"TCP ({target[0]:.4g}, {target[1]:.4g}) m at t = {reference.time[i]:.4g} s",
                "is out of the crane's reach (inverse kinematics did not converge)",
            )
        theta[i, :2] = current
    # rates: the tracked coordinates are linear in dtheta and ddtheta (columns 3-5, 6-8)
    zero = np.zeros((n, 3))
    s0 = kin.samples(theta, zero, zero)
    jac = s0.d_velocity[:, :, 3:6]
    dtheta = np.asarray(np.linalg.solve(jac, reference.velocity[..., None])[..., 0], dtype=float)
    s1 = kin.samples(theta, dtheta, zero)
    rhs = (reference.acceleration - s1.acceleration)[..., None]
    ddtheta = np.asarray(np.linalg.solve(jac, rhs)[..., 0], dtype=float)
    return JointTrajectory(reference.time, theta, dtheta, ddtheta)


def fit_coefficients(basis: SplineBasis, joints: JointTrajectory, rate_weight: float = 0.1) -> Array:
    """Least-squares spline coefficients (n_joints, n) for dense joint samples, at rest at both ends.

    Minimises sum |B c - theta|^2 + w^2 |dB c - dtheta|^2 + w^4 |ddB c - ddtheta|^2 (w =
    ``rate_weight`` [s]) subject to dtheta = ddtheta = 0 at t = 0 and t = duration (linear).
    """
    B, dB, ddB = basis.matrices(joints.time)
    w = rate_weight
    lhs = np.vstack([B, w * dB, w**2 * ddB])
    ends = np.array([0.0, basis.duration])
    E = np.vstack([basis.matrix(ends, 1), basis.matrix(ends, 2)])
    kkt = np.block([[lhs.T @ lhs, E.T], [E, np.zeros((len(E), len(E)))]])
    out = np.zeros((joints.position.shape[1], basis.n))
    for j in range(joints.position.shape[1]):
        rhs = np.concatenate([joints.position[:, j], w * joints.velocity[:, j], w**2 * joints.acceleration[:, j]])
        sol = np.linalg.solve(kkt, np.concatenate([lhs.T @ rhs, np.zeros(len(E))]))
        out[j] = sol[: basis.n]
    return out

"""The NLP of seed eq. ``costf2`` subject to ``const_a``..``const_m``: cost, constraints, exact gradients.

Decision variables z = [z_xi (6), z_c (3 N)] (scaled): Xi = ``XI_SCALE`` z_xi [m] (lift L, Lc0,
Lc, then tilt) and c = c_ref + ``C_SCALE`` z_c, the B-spline coefficients of theta1, theta2, xt2
around the study's initial fit. The cost f = 1/2 Dt sum_k (sum_i P_i(t_k))^2 [W^2 s] uses the EMLA
electrical power P_i of :mod:`hiab_sim.emla` (never f v / eta); it is a squared-power integral,
not an energy, and is scaled by its value at the study's start.

Constraints, all scaled to O(1) and written g(z) >= 0 (rows named in :attr:`constraint_names`):

* ``const_a``: [f_x, v_x, a_x] = ID(theta, dtheta, ddtheta, robot(Xi)), implicit (evaluated);
* ``const_b``..``const_d``: |r(theta) - r_ref| <= tolerance for position, velocity and
  acceleration of r = (x_tcp, y_tcp, xt2) at every collocation point (a tolerance band, because
  156 equalities over-determine 66 coefficients); rest at both ends as 12 linear equalities;
* ``const_e``, ``const_f``: the EMLA envelope margins (peak torque, rated speed, voltage) >= 0;
* ``const_g``: Xi within [xi_low, xi_up] (variable bounds);
* ``const_h``: theta within the crane's joint range and the triangle margin (linear in c);
* ``const_i``: |dtheta| <= joint velocity limit (linear in c);
* ``const_j``: 0 <= x <= Lc and x <= stroke at every sample, and at both ends of the working range;
* ``const_k``: the interior angle at the boom hinge within [margin, pi - margin] (it depends on
  theta only, so it is part of ``const_h``), which keeps Lc0 + x + Lc < L + L1;
* ``const_l``, ``const_m`` hold by construction: the chain is solved from its triangle.

Gradients: per-sample ID partials by batched central differences (all samples and all 9
perturbations in one ID call), chained through the B-spline matrices (exact); Xi partials by
central differences (on the analytic path, which agrees with the MuJoCo path to ~1e-14 relative, or
with MuJoCo model rebuilds); EMLA and kinematic partials analytic.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from hiab_sim.crane.description import CHAIN_NAMES, Crane, LinkLengths
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples
from hiab_sim.emla import (
    ENVELOPE_LIMIT_NAMES,
    EmlaSet,
    electrical_power,
    electrical_power_partials,
    envelope_margin_partials,
    envelope_margins,
)
from hiab_sim.errors import InvalidInputError
from hiab_sim.study import trajectory as tr
from hiab_sim.study.config import Study

Array = NDArray[np.float64]
IdFunction = Callable[[JointSamples], ActuatorSamples]

#: Scale of the link-length variables [m per unit].
XI_SCALE = 1.0
#: Scale of the spline-coefficient variables [rad or m per unit] (chosen for fast SQP convergence).
C_SCALE = 0.1
#: Scale of the stroke constraints [m per unit].
STROKE_SCALE = 0.1
ACTUATORS = ("lift", "tilt", "telescope")
#: The ID's input check uses the working range shrunk by this much at both ends [rad].
ID_SLACK = 0.02
#: The optimiser (``tightened``) holds const_j at the ends of the working range with this clearance
#: [m], so that its optimum passes the crane's exact stroke check despite SLSQP's round-off-level
#: violations. It is part of the solver's rows only: start checks and reported violations
#: (:meth:`LinkLengthProblem.margins`) use the nominal const_j, so the built crane, whose strokes reach
#: exactly 0 and the full stroke at the ends of its joint range, is a start with violation ~0.
WORKING_CLEARANCE = 1e-6


def make_id(crane: Crane, lengths: LinkLengths, path: str, tcp_force: Array | None) -> IdFunction:
    """Inverse dynamics (seed eq. ``dynamics``) for one link-length set, by ``path``."""
    if path == "mujoco":
        from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics

        model = MujocoInverseDynamics(crane, lengths)
        return lambda joints: model(joints, tcp_force=tcp_force)
    if path == "analytic":
        from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics

        return lambda joints: analytic_inverse_dynamics(crane, lengths, joints, tcp_force=tcp_force)
    raise InvalidInputError("id_path", path, "must be 'mujoco' or 'analytic'")


@dataclass(frozen=True)
class Evaluation:
    """Everything computed at one point z (unscaled quantities in SI units)."""

    z: Array
    lengths: LinkLengths
    coefficients: Array  # (3, N)
    joints: tr.JointTrajectory
    tcp: tr.TcpSamples
    actuators: ActuatorSamples
    power: Array  # (K, 3) electrical power [W]
    cost: float  # [W^2 s]
    constraints: Array  # scaled, feasible where >= 0
    equalities: Array  # scaled, feasible where == 0


def working_range(crane: Crane, joints: Array, margin: float) -> tuple[tuple[float, float], ...]:
    """Joint range the design must serve: the samples' range widened by ``margin`` [rad]."""
    out = []
    for j, chain in enumerate(crane.chains):
        lo, hi = chain.joint_range
        out.append((max(lo, float(joints[:, j].min()) - margin), min(hi, float(joints[:, j].max()) + margin)))
    return tuple(out)


class LinkLengthProblem:
    """The scaled NLP of one study on a time grid (collocation grid by default).

    Args:
        study: The study.
        emlas: EMLA set (default: the study's).
        id_path: ``mujoco`` or ``analytic`` (default: the study's).
        times: Sample times [s] (default: the collocation grid); Dt of the cost is their step.
        cost_scale: Divisor of the cost [W^2 s] (default: its value at the study's start).
        tightened: Hold the tracking bands times ``collocation_fraction`` and the envelope margins
            >= ``envelope_margin`` (the optimiser's grid); False for the nominal re-check.

    """

    def __init__(
        self,
        study: Study,
        emlas: EmlaSet | None = None,
        id_path: str | None = None,
        times: Array | None = None,
        cost_scale: float | None = None,
        tightened: bool = True,
    ) -> None:
        self.study = study
        self.band_fraction = study.tracking.collocation_fraction if tightened else 1.0
        self.envelope_margin = study.bounds.envelope_margin if tightened else 0.0
        self.working_clearance = WORKING_CLEARANCE / STROKE_SCALE if tightened else 0.0
        self.emlas = emlas or study.emlas
        self.id_path = id_path or study.solver.id_path
        self.times = study.grid.times() if times is None else np.asarray(times, dtype=float)
        self.dt = float(self.times[1] - self.times[0])
        self.basis = tr.SplineBasis(study.spline.control_points, study.spline.degree, study.grid.duration)
        self.B = np.stack(self.basis.matrices(self.times))  # (3 orders, K, N)
        self.kin = tr.TcpKinematics(study.crane)
        self.reference = tr.spiral_reference(self.kin, study.reference, study.grid.duration, self.times)
        self.tcp_force = study.tcp_force
        self.fd_step = study.solver.fd_step
        self.xi_path = "analytic" if study.solver.xi_derivatives == "analytic" else self.id_path
        # initial fit: inverse kinematics on the fine grid, least-squares spline at rest at both ends
        fine = study.grid.fine_times()
        fine_ref = tr.spiral_reference(self.kin, study.reference, study.grid.duration, fine)
        assert study.reference.centre_joints is not None or study.reference.centre_tcp is not None
        guess = study.reference.centre_joints or _centre_guess(study)
        ik = tr.inverse_kinematics(self.kin, fine_ref, guess)
        self.reference_joints = ik
        self.c_ref = tr.fit_coefficients(self.basis, ik)
        margin = study.bounds.triangle_margin
        # const_h with const_k: the crane's joint range and the hinge-angle margin (theta only)
        self.theta_low = np.zeros(3)
        self.theta_up = np.zeros(3)
        for j, chain in enumerate(study.crane.chains):
            lo, hi = chain.joint_range
            self.theta_low[j] = max(lo, chain.joint_offset - math.pi + margin)
            self.theta_up[j] = min(hi, chain.joint_offset - margin)
        self.theta_low[2], self.theta_up[2] = study.crane.telescope.joint_range
        # working range the design must serve (const_j at its ends): the crane's full joint range
        # (so the redesigned crane keeps its workspace, as every ID path's input check demands) or
        # the reference's range widened by a margin. The ID sees a slightly narrower range, so trial
        # points of the line search that violate const_j by a second-order amount stay evaluable.
        wr_margin = study.bounds.working_margin
        if study.bounds.working_range == "crane":
            self.working = tuple(chain.joint_range for chain in study.crane.chains)
            inner = tuple((lo + ID_SLACK, hi - ID_SLACK) for lo, hi in self.working)
        else:
            self.working = working_range(study.crane, ik.position, wr_margin)
            inner = working_range(study.crane, ik.position, 0.5 * wr_margin)
        self.crane = replace(
            study.crane,
            lift=replace(study.crane.lift, joint_range=inner[0]),
            tilt=replace(study.crane.tilt, joint_range=inner[1]),
        )
        self.n_xi = 6
        self.n_c = 3 * self.basis.n
        self.n = self.n_xi + self.n_c
        self.lower = np.concatenate([np.asarray(study.bounds.xi_low) / XI_SCALE, np.full(self.n_c, -np.inf)])
        self.upper = np.concatenate([np.asarray(study.bounds.xi_up) / XI_SCALE, np.full(self.n_c, np.inf)])
        self._id_cache: dict[bytes, IdFunction] = {}
        self._eval_cache: dict[bytes, Evaluation] = {}
        self._grad_cache: dict[bytes, tuple[Array, Array]] = {}
        self.constraint_names = self._names()
        #: added to the solver's rows gives the nominal scaled margins (the clearance rows are last)
        self.clearance = np.zeros(len(self.constraint_names))
        assert all(name.startswith("working_range.") for name in self.constraint_names[-12:])
        self.clearance[-12:] = self.working_clearance
        self.n_evaluations = 0
        self.n_gradients = 0
        self.cost_scale = 1.0
        if cost_scale is None:
            try:
                cost_scale = self.evaluate(self.initial_point(study.initial_lengths)).cost
            except InvalidInputError as error:
                raise InvalidInputError(
                    f"initial_lengths ({error.field})",
                    error.value,
                    f"the start is not an admissible crane: {error.allowed}",
                ) from None
        self.cost_scale = max(float(cost_scale), 1e-300)

    # -- variables ---------------------------------------------------------------------------

    def initial_point(self, lengths: LinkLengths, coefficients: Array | None = None) -> Array:
        """Scaled z for link lengths and coefficients (default: the inverse-kinematics fit)."""
        c = self.c_ref if coefficients is None else np.asarray(coefficients, dtype=float).reshape(3, -1)
        return np.concatenate([lengths.as_array() / XI_SCALE, ((c - self.c_ref) / C_SCALE).ravel()])

    def unpack(self, z: Array) -> tuple[LinkLengths, Array]:
        """(Xi, c (3, N)) from scaled z."""
        z = np.asarray(z, dtype=float)
        xi = z[: self.n_xi] * XI_SCALE
        c = self.c_ref + C_SCALE * z[self.n_xi :].reshape(3, self.basis.n)
        return LinkLengths.from_array(xi), c

    # -- evaluation --------------------------------------------------------------------------

    def _id(self, lengths: LinkLengths) -> IdFunction:
        key = lengths.as_array().tobytes()
        if key not in self._id_cache:
            if len(self._id_cache) > 32:
                self._id_cache.clear()
            self._id_cache[key] = make_id(self.crane, lengths, self.id_path, self.tcp_force)
        return self._id_cache[key]

    def joints(self, c: Array) -> tr.JointTrajectory:
        """Joint samples on this problem's grid for coefficients c (3, N)."""
        B, dB, ddB = self.B
        return tr.JointTrajectory(self.times, B @ c.T, dB @ c.T, ddB @ c.T)

    def evaluate(self, z: Array) -> Evaluation:
        """Cost, constraints and intermediate quantities at z (cached by value)."""
        z = np.array(z, dtype=float)
        key = z.tobytes()
        if key in self._eval_cache:
            return self._eval_cache[key]
        self.n_evaluations += 1
        lengths, c = self.unpack(z)
        joints = self.joints(c)
        act = self._id(lengths)(JointSamples(joints.position, joints.velocity, joints.acceleration))
        tcp = self.kin.samples(joints.position, joints.velocity, joints.acceleration)
        power = np.column_stack(
            [
                electrical_power(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
                for i, p in enumerate(self.emlas)
            ]
        )
        total = power.sum(axis=1)
        cost = 0.5 * self.dt * float(np.sum(total**2))
        g = self._constraints(lengths, joints, tcp, act)
        e = self._equalities(c)
        ev = Evaluation(z, lengths, c, joints, tcp, act, power, cost, g, e)
        if len(self._eval_cache) > 8:
            self._eval_cache.clear()
        self._eval_cache[key] = ev
        return ev

    def cost(self, z: Array) -> float:
        """Scaled cost f / f_scale."""
        return self.evaluate(z).cost / self.cost_scale

    def constraints(self, z: Array) -> Array:
        """Scaled inequality constraints g(z) >= 0."""
        return self.evaluate(z).constraints

    def equalities(self, z: Array) -> Array:
        """Rest-to-rest equalities (linear in c)."""
        return self.evaluate(z).equalities

    def margins(self, z: Array) -> Array:
        """Nominal scaled inequality margins (feasible where >= 0): the solver's rows without the clearance.

        The tracking bands and envelope margins stay as this problem holds them (``tightened``);
        only the working-range clearance, a safety the optimiser adds for its own optimum, is removed.
        """
        return self.evaluate(z).constraints + self.clearance

    def max_violation(self, z: Array) -> float:
        """Largest violation of any nominal constraint (:meth:`margins`) or bound, in scaled units."""
        ev = self.evaluate(z)
        v = max(0.0, float(-self.margins(z).min()), float(np.abs(ev.equalities).max()))
        zx = np.asarray(z)[: self.n_xi]
        return max(v, float(np.max(self.lower[: self.n_xi] - zx)), float(np.max(zx - self.upper[: self.n_xi])))

    def _constraints(
        self, lengths: LinkLengths, joints: tr.JointTrajectory, tcp: tr.TcpSamples, act: ActuatorSamples
    ) -> Array:
        return np.concatenate([block for block, _ in self._constraint_blocks(lengths, joints, tcp, act)])

    def _constraint_blocks(
        self, lengths: LinkLengths, joints: tr.JointTrajectory, tcp: tr.TcpSamples, act: ActuatorSamples
    ) -> list[tuple[Array, str]]:
        """Constraint values in row order, (K, m) blocks flattened per sample."""
        tol = self.study.tracking
        ref = self.reference
        blocks: list[tuple[Array, str]] = []
        for value, target, band, name in (
            (tcp.position, ref.position, tol.position, "position"),
            (tcp.velocity, ref.velocity, tol.velocity, "velocity"),
            (tcp.acceleration, ref.acceleration, tol.acceleration, "acceleration"),
        ):
            err = (value - target) / (band * self.band_fraction)
            blocks.append((np.concatenate([1.0 - err, 1.0 + err], axis=1).ravel(), name))
        env = np.stack(
            [
                envelope_margins(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
                for i, p in enumerate(self.emlas)
            ],
            axis=1,
        )  # (3 limits, 3 actuators, K)
        env = (env - self.envelope_margin) / (1.0 - self.envelope_margin)
        blocks.append((np.transpose(env, (2, 1, 0)).reshape(len(self.times), 9).ravel(), "envelope"))
        x = self._strokes(lengths, joints.position)  # (K, 2)
        blocks.append((self._stroke_rows(lengths, x).ravel(), "stroke"))
        th = joints.position
        blocks.append((np.concatenate([th - self.theta_low, self.theta_up - th], axis=1).ravel(), "joint"))
        vmax = np.asarray(self.study.bounds.joint_velocity)
        dth = joints.velocity / vmax
        blocks.append((np.concatenate([1.0 - dth, 1.0 + dth], axis=1).ravel(), "joint_velocity"))
        xw = self._strokes(lengths, np.array([[w[0] for w in self.working], [w[1] for w in self.working]]))
        blocks.append((self._stroke_rows(lengths, xw).ravel() - self.working_clearance, "working_range"))
        return blocks

    def _strokes(self, lengths: LinkLengths, theta: Array) -> Array:
        """Strokes x (K, 2) of lift and tilt from joint angles (eqs. thetas, qus_a)."""
        from hiab_sim.crane import mechanism

        return np.column_stack(
            [
                mechanism.joint_to_stroke(ch, getattr(lengths, ch.name), theta[:, j])
                for j, ch in enumerate(self.crane.chains)
            ]
        )

    def _stroke_rows(self, lengths: LinkLengths, x: Array) -> Array:
        """const_j per chain: x >= 0, Lc - x >= 0, stroke - x >= 0, as (K, 6) scaled."""
        cols = []
        for j, chain in enumerate(self.crane.chains):
            xi = getattr(lengths, chain.name)
            cols += [x[:, j], xi.Lc - x[:, j], chain.stroke - x[:, j]]
        return np.column_stack(cols) / STROKE_SCALE

    def _equalities(self, c: Array) -> Array:
        return (self._rest_matrix() @ c.T).ravel() / C_SCALE

    def _rest_matrix(self) -> Array:
        ends = np.array([0.0, self.basis.duration])
        return np.vstack([self.basis.matrix(ends, 1), self.basis.matrix(ends, 2)])  # (4, N)

    def _names(self) -> list[str]:
        names: list[str] = []
        k_times = self.times
        coords = ("x_tcp", "y_tcp", "xt2")
        for order in ("position", "velocity", "acceleration"):
            for t in k_times:
                names += [f"tracking.{order}.{c} <= band at t={t:.4g} s" for c in coords]
                names += [f"tracking.{order}.{c} >= -band at t={t:.4g} s" for c in coords]
        for t in k_times:
            names += [f"envelope.{a}.{lim} at t={t:.4g} s" for a in ACTUATORS for lim in ENVELOPE_LIMIT_NAMES]
        stroke_names = [f"{ch}.{w}" for ch in CHAIN_NAMES for w in ("x >= 0", "x <= Lc", "x <= stroke")]
        for t in k_times:
            names += [f"stroke.{s} at t={t:.4g} s" for s in stroke_names]
        joint_names = ("theta1", "theta2", "xt2")
        for t in k_times:
            names += [f"joint.{j} >= low at t={t:.4g} s" for j in joint_names]
            names += [f"joint.{j} <= up at t={t:.4g} s" for j in joint_names]
        for t in k_times:
            names += [f"joint_velocity.{j} <= limit at t={t:.4g} s" for j in joint_names]
            names += [f"joint_velocity.{j} >= -limit at t={t:.4g} s" for j in joint_names]
        for end in ("low", "up"):
            names += [f"working_range.{s} at the {end} end" for s in stroke_names]
        return names

    # -- gradients ---------------------------------------------------------------------------

    def cost_gradient(self, z: Array) -> Array:
        """d(scaled cost)/dz."""
        return self._gradients(z)[0]

    def constraints_jacobian(self, z: Array) -> Array:
        """D g / dz, shape (m, n)."""
        return self._gradients(z)[1]

    def equalities_jacobian(self, z: Array) -> Array:
        """D e / dz (constant), shape (12, n)."""
        R = self._rest_matrix()  # (4, N)
        jac = np.zeros((12, self.n))
        for j in range(3):
            jac[j * 4 : (j + 1) * 4, self.n_xi + j * self.basis.n : self.n_xi + (j + 1) * self.basis.n] = R
        # rows of _equalities are (R @ c.T).ravel(): row r, joint j -> index r * 3 + j
        order = np.array([r * 3 + j for j in range(3) for r in range(4)])
        out = np.zeros_like(jac)
        out[order] = jac
        return out

    def _sample_partials(self, lengths: LinkLengths, joints: tr.JointTrajectory) -> Array:
        """d(f, v, a)/d(theta, dtheta, ddtheta) per sample by central differences, (K, 9, 9).

        All K samples and all 9 perturbations go into one ID call of 18 K samples: samples are
        independent, so perturbing them together is exact bookkeeping, not an approximation.
        """
        K = len(self.times)
        base = np.concatenate([joints.position, joints.velocity, joints.acceleration], axis=1)  # (K, 9)
        h = self.fd_step * np.maximum(1.0, np.abs(base))  # (K, 9)
        batch = np.repeat(base[None], 18, axis=0)  # (18, K, 9)
        for j in range(9):
            batch[2 * j, :, j] += h[:, j]
            batch[2 * j + 1, :, j] -= h[:, j]
        flat = batch.reshape(18 * K, 9)
        act = self._id(lengths)(JointSamples(flat[:, 0:3], flat[:, 3:6], flat[:, 6:9]))
        out = np.concatenate([act.force, act.velocity, act.acceleration], axis=1).reshape(18, K, 9)
        d = (out[0::2] - out[1::2]) / (2.0 * h.T[:, :, None])  # (9 inputs, K, 9 outputs)
        return np.transpose(d, (1, 2, 0))

    def _xi_partials(self, lengths: LinkLengths, joints: tr.JointTrajectory) -> Array:
        """d(f, v, a)/dXi per sample by central differences, (K, 9, 6) [per m].

        On the analytic path (no model to rebuild) or, with ``xi_derivatives: rebuild``, on the
        optimisation's own path with one model build per perturbed Xi.
        """
        xi = lengths.as_array()
        js = JointSamples(joints.position, joints.velocity, joints.acceleration)
        out = np.zeros((len(self.times), 9, 6))
        for i in range(6):
            h = self.fd_step * max(1.0, abs(xi[i]))
            values = []
            for sign in (1.0, -1.0):
                x = xi.copy()
                x[i] += sign * h
                model = make_id(self.crane, LinkLengths.from_array(x), self.xi_path, self.tcp_force)
                a = model(js)
                values.append(np.concatenate([a.force, a.velocity, a.acceleration], axis=1))
            out[:, :, i] = (values[0] - values[1]) / (2.0 * h)
        return out

    def _gradients(self, z: Array) -> tuple[Array, Array]:
        z = np.array(z, dtype=float)
        key = z.tobytes()
        if key in self._grad_cache:
            return self._grad_cache[key]
        self.n_gradients += 1
        ev = self.evaluate(z)
        lengths, joints, act = ev.lengths, ev.joints, ev.actuators
        K = len(self.times)
        dY = self._sample_partials(lengths, joints)  # (K, 9 out, 9 in)
        dYxi = self._xi_partials(lengths, joints) * XI_SCALE  # (K, 9, 6) per scaled unit
        # EMLA partials per actuator: dP/d(f, v, a) and dg/d(f, v, a)
        dP = np.zeros((K, 3, 9))  # power of actuator i w.r.t. Y (f0 f1 f2 v0 v1 v2 a0 a1 a2)
        dG = np.zeros((K, 3, 3, 9))  # margins (actuator, limit) w.r.t. Y
        for i, p in enumerate(self.emlas):
            f, v, a = act.force[:, i], act.velocity[:, i], act.acceleration[:, i]
            pf, pv, pa = electrical_power_partials(p, f, v, a)
            dP[:, i, i], dP[:, i, 3 + i], dP[:, i, 6 + i] = pf, pv, pa
            gf, gv, ga = envelope_margin_partials(p, f, v, a)  # each (3 limits, K)
            dG[:, i, :, i], dG[:, i, :, 3 + i], dG[:, i, :, 6 + i] = gf.T, gv.T, ga.T
        total = ev.power.sum(axis=1)
        dcost_dY = self.dt * total[:, None] * dP.sum(axis=1)  # (K, 9)
        # per-sample derivative tensors w.r.t. q9 = (theta, dtheta, ddtheta) and scaled Xi
        rows_q: list[Array] = []  # each (K, m, 9)
        rows_xi: list[Array] = []  # each (K, m, 6)
        tol = self.study.tracking
        for d, band in (
            (ev.tcp.d_position, tol.position),
            (ev.tcp.d_velocity, tol.velocity),
            (ev.tcp.d_acceleration, tol.acceleration),
        ):
            b = band * self.band_fraction
            rows_q.append(np.concatenate([-d / b, d / b], axis=1))
            rows_xi.append(np.zeros((K, 6, 6)))
        dGY = dG.reshape(K, 9, 9) / (1.0 - self.envelope_margin)
        rows_q.append(np.einsum("kmy,kyq->kmq", dGY, dY))
        rows_xi.append(np.einsum("kmy,kyx->kmx", dGY, dYxi))
        sq, sxi = self._stroke_partials(lengths, joints.position)
        rows_q.append(sq)
        rows_xi.append(sxi)
        eye = np.eye(3)
        jq = np.zeros((K, 6, 9))
        jq[:, :3, :3], jq[:, 3:, :3] = eye, -eye
        rows_q.append(jq)
        rows_xi.append(np.zeros((K, 6, 6)))
        vmax = np.asarray(self.study.bounds.joint_velocity)
        vq = np.zeros((K, 6, 9))
        vq[:, :3, 3:6], vq[:, 3:, 3:6] = -np.diag(1.0 / vmax), np.diag(1.0 / vmax)
        rows_q.append(vq)
        rows_xi.append(np.zeros((K, 6, 6)))
        Dq = np.concatenate(rows_q, axis=1)  # (K, m_per_sample, 9)
        Dxi = np.concatenate(rows_xi, axis=1)
        m_s = Dq.shape[1]
        # chain through the spline matrices: q9 index = order * 3 + joint
        Dc = np.einsum("kmoj,okn->kmjn", Dq.reshape(K, m_s, 3, 3), self.B) * C_SCALE
        per_sample = np.concatenate([Dxi, Dc.reshape(K, m_s, self.n_c)], axis=2)  # (K, m_s, n)
        # reorder rows to the block order of _constraint_blocks: block-major, then sample-major
        sizes = [6, 6, 6, 9, 6, 6, 6]
        starts = np.cumsum([0, *sizes])
        jac_blocks = [per_sample[:, starts[b] : starts[b + 1], :].reshape(-1, self.n) for b in range(len(sizes))]
        wxi = self._working_partials(lengths)
        jac_blocks.append(np.concatenate([wxi, np.zeros((wxi.shape[0], self.n_c))], axis=1))
        jac = np.concatenate(jac_blocks, axis=0)
        # cost gradient
        dcost_q = np.einsum("ky,kyq->kq", dcost_dY, dY)
        grad_c = np.einsum("koj,okn->jn", dcost_q.reshape(K, 3, 3), self.B).ravel() * C_SCALE
        grad_xi = np.einsum("ky,kyx->x", dcost_dY, dYxi)
        grad = np.concatenate([grad_xi, grad_c]) / self.cost_scale
        if len(self._grad_cache) > 4:
            self._grad_cache.clear()
        self._grad_cache[key] = (grad, jac)
        return grad, jac

    def _stroke_partials(self, lengths: LinkLengths, theta: Array) -> tuple[Array, Array]:
        """Partials of the (K, 6) stroke rows w.r.t. q9 (K, 6, 9) and scaled Xi (K, 6, 6)."""
        K = theta.shape[0]
        dq = np.zeros((K, 6, 9))
        dxi = np.zeros((K, 6, 6))
        for j, chain in enumerate(self.crane.chains):
            xi = getattr(lengths, chain.name)
            q = chain.joint_offset - math.pi - theta[:, j]
            s = np.sqrt(xi.L**2 + chain.L1**2 - 2.0 * xi.L * chain.L1 * np.cos(q))
            dx_dtheta = -xi.L * chain.L1 * np.sin(q) / s
            dx_dL = (xi.L - chain.L1 * np.cos(q)) / s
            dx_dxi = np.column_stack([dx_dL, -np.ones(K), -np.ones(K)])  # (K, 3): L, Lc0, Lc
            r = 3 * j
            dq[:, r, j], dq[:, r + 1, j], dq[:, r + 2, j] = dx_dtheta, -dx_dtheta, -dx_dtheta
            cols = slice(3 * j, 3 * j + 3)
            dxi[:, r, cols] = dx_dxi
            dxi[:, r + 1, cols] = -dx_dxi
            dxi[:, r + 1, 3 * j + 2] += 1.0
            dxi[:, r + 2, cols] = -dx_dxi
        return dq / STROKE_SCALE, dxi * XI_SCALE / STROKE_SCALE

    def _working_partials(self, lengths: LinkLengths) -> Array:
        """Partials of the working-range rows w.r.t. scaled Xi, (12, 6); they do not depend on c."""
        theta = np.array([[w[0] for w in self.working] + [0.0], [w[1] for w in self.working] + [0.0]])
        return self._stroke_partials(lengths, theta)[1].reshape(-1, 6)


def _centre_guess(study: Study) -> tuple[float, float]:
    """Initial joint guess for a spiral centred at a TCP point: the middle of the joint ranges."""
    lo1, hi1 = study.crane.lift.joint_range
    lo2, hi2 = study.crane.tilt.joint_range
    return (0.5 * (lo1 + hi1), 0.5 * (lo2 + hi2))

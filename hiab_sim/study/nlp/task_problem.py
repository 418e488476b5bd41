"""One task's rows and cost of the seed's NLP (eq. ``costf2`` subject to ``const_a``..``const_m``), exact gradients.

The solvers, reports and analyses take :class:`hiab_sim.study.nlp.problem.StudyProblem`, which stacks
one :class:`TaskProblem` per task over the shared Xi (a single task is its own study, bit for bit).

Decision variables z = [z_xi (n_xi), z_c (n N)] (scaled): Xi = ``XI_SCALE`` z_xi (the machine's
decision variables: for the crane lift L, Lc0, Lc, then tilt [m]) and c = c_ref + ``C_SCALE`` z_c,
the B-spline coefficients of the n joints (the crane's theta1, theta2, xt2) around the study's
initial fit. The machine is seen through :class:`hiab_sim.study.machines.protocol.StudyMachine`.
The cost f = 1/2 Dt sum_k (sum_i P_i(t_k))^2 [W^2 s] uses the EMLA
electrical power P_i of :mod:`hiab_sim.emla` (never f v / eta); it is a squared-power integral,
not an energy, and is scaled by its value at the study's start.

Constraints, all scaled to O(1) and written g(z) >= 0 (rows named in :attr:`constraint_names`):

* ``const_a``: [f_x, v_x, a_x] = ID(theta, dtheta, ddtheta, robot(Xi)), implicit (evaluated);
* ``const_b``..``const_d``: |r - r_ref| <= tolerance (a band: equalities would over-determine the
  spline) for position, velocity and acceleration of the tracked r at every collocation point;
  rest at both ends as 4 n linear equalities;
* ``const_e``, ``const_f``: the EMLA envelope margins (peak torque, rated speed, voltage) >= 0;
* ``const_g``: Xi within [xi_low, xi_up] (variable bounds);
* ``const_h``: theta within the machine's joint range and a triangle's margin (linear in c);
* ``const_i``: |dtheta| <= joint velocity limit (linear in c);
* ``const_j``: 0 <= x <= Lc and x <= stroke at every sample, and at both ends of the working range;
* ``const_k``: the interior angle at the boom hinge within [margin, pi - margin] (it depends on
  theta only, so it is part of ``const_h``), which keeps Lc0 + x + Lc < L + L1;
* ``const_l``, ``const_m`` hold by construction (the chain is solved from its loop closure).

Each inequality group is a constraint block (:mod:`hiab_sim.study.constraints.blocks`) and the cost an objective
(:mod:`hiab_sim.study.nlp.objectives`); the block registry
(:data:`hiab_sim.study.constraints.block_registry.BLOCKS`) lists the blocks once, and row names, row layout,
clearances and the Jacobian follow from that list (:class:`~hiab_sim.study.nlp.interface.BlockLayout`).

Gradients: per-sample ID partials by batched central differences (all samples and all 3 n
perturbations in one ID call), chained through the B-spline matrices (exact); Xi partials by
central differences (on the analytic path, which agrees with the MuJoCo path to ~1e-14 relative, or
with MuJoCo model rebuilds); EMLA and kinematic partials analytic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.dynamics.interface import InverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla import (
    EmlaSet,
    electrical_power,
)
from hiab_sim.emla.duty_energy import drive_duty
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.constraints import blocks as bl
from hiab_sim.study.constraints import builtin_blocks  # noqa: F401  (registers the built-in blocks, in row order)
from hiab_sim.study.constraints.block_registry import BlockFactory, build_blocks
from hiab_sim.study.machines.protocol import Design
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.motion.spline_chain import SplineChain
from hiab_sim.study.nlp.id_partials import id_joint_partials
from hiab_sim.study.nlp.interface import (
    BlockJacobian,
    BlockLayout,
    ConstraintBlock,
    SamplePartials,
    SampleRows,
    SampleState,
    ScaledProblem,
)
from hiab_sim.study.nlp.objectives import make_objective
from hiab_sim.study.nlp.task_setup import (
    check_reference_ranges,
    duty_options,
    reference_joints,
    served_ranges,
    start_error,
)
from hiab_sim.study.spec.study_file import Study
from hiab_sim.study.spec.tasks import Task

#: Scale of the link-length variables [m per unit].
XI_SCALE = 1.0
#: Scale of the spline-coefficient variables [rad or m per unit] (chosen for fast SQP convergence).
C_SCALE = 0.1
STROKE_SCALE = bl.STROKE_SCALE
#: The optimiser (``tightened``) holds const_j at the ends of the working range with this clearance [m] (its
#: optimum passes the exact stroke check despite SLSQP's round-off); the solver's rows only: start checks and
#: reported violations (:meth:`TaskProblem.margins`) use the nominal const_j (the built machine: violation ~0).
WORKING_CLEARANCE = 1e-6


@dataclass(frozen=True)
class Evaluation(SampleState):
    """Everything computed at one point z (unscaled quantities in SI units): the state and its rows."""

    z: Array
    coefficients: Array  # (n, N)
    cost: float  # the objective's value [its unit; W^2 s for costf2]
    constraints: Array  # scaled, feasible where >= 0
    equalities: Array  # scaled, feasible where == 0


class TaskProblem(ScaledProblem):
    """The scaled rows and cost of one task of a study on a time grid (its collocation grid by default).

    Args:
        study: The study.
        emlas: EMLA set (default: the study's own).
        id_path: ``mujoco`` or ``analytic`` (default: the study's).
        times: Sample times [s] (default: the collocation grid); Dt of the cost is their step.
        cost_scale: Divisor of the cost [the objective's unit] (default: its value at the study's start).
        tightened: Hold the tracking bands times ``collocation_fraction`` and the envelope margins
            >= ``envelope_margin`` (the optimiser's grid); False for the nominal re-check.
        objective: Name of the objective (:data:`hiab_sim.study.nlp.objectives.OBJECTIVES`; default: the study's).
        task: The task whose NLP this is (default: the study's only task). Its grid is the study's
            step over the task's duration, its spline the study's density of control points (or
            the task's own), its reference and payload force its own (:meth:`Task.id_force`);
            :class:`hiab_sim.study.nlp.problem.StudyProblem` composes one problem per task.
        extra_blocks: Blocks of this problem only, after the registered ones (a Pareto point's bound).

    """

    def __init__(
        self,
        study: Study,
        emlas: EmlaSet | None = None,
        id_path: str | None = None,
        times: Array | None = None,
        cost_scale: float | None = None,
        tightened: bool = True,
        objective: str | None = None,
        task: Task | None = None,
        extra_blocks: BlockFactory | None = None,
    ) -> None:
        if task is None:
            if len(study.tasks) != 1:
                raise InvalidInputError("task", len(study.tasks), "a study of several tasks needs a task per problem")
            task = study.tasks[0]
        self.study = study
        self.task = task
        self._extra_blocks = extra_blocks  # one problem's own rows after the registered ones (a Pareto point's)
        self.tightened = tightened
        self.band_fraction = study.tracking.collocation_fraction if tightened else 1.0
        self.envelope_margin = study.bounds.envelope_margin if tightened else 0.0
        self.working_clearance = WORKING_CLEARANCE / STROKE_SCALE if tightened else 0.0
        self.emlas = emlas if emlas is not None else study.emlas
        self.id_path = id_path or study.solver.id_path
        # the task's collocation grid: the study's step over the task's duration (the study's grid for
        # one task of the grid's duration), its spline: the study's density of control points
        self.collocation_times = task.times(study.grid.dt)
        self.times = self.collocation_times if times is None else np.asarray(times, dtype=float)
        self.dt = float(self.times[1] - self.times[0])
        duration = task.reference.duration
        points = task.spline_points(study.spline.control_points, study.grid.duration, study.spline.degree)
        self.basis = tr.SplineBasis(points, study.spline.degree, duration)
        self.B = np.stack(self.basis.matrices(self.times))  # (3 orders, K, N)
        model = study.model
        self.n_joints = len(model.joint_names)
        self.kin = model.kinematics
        self.reference = task.reference.sample(self.kin, self.times)
        self.tcp_force = task.id_force(self.kin, model.gravity, self.times)
        self.fd_step = study.solver.fd_step
        self.xi_path = "analytic" if study.solver.xi_derivatives == "analytic" else self.id_path
        # unset: the analytic path on a machine file, the optimisation's own on a crane file (SolverSettings)
        joint = study.solver.joint_derivatives or ("path" if getattr(model, "crane", None) is not None else "analytic")
        self.q_path = "analytic" if joint == "analytic" else self.id_path
        # initial fit: inverse kinematics on the fine grid, least-squares spline at rest at both ends
        fine_ref = task.reference.sample(self.kin, self.fine_times())
        ik = reference_joints(study, task, fine_ref)
        self.reference_joints = ik
        self.c_ref = tr.fit_coefficients(self.basis, ik)
        # const_h with const_k: the machine's joint range and a triangle's hinge-angle margin (q only)
        self.theta_low, self.theta_up = model.joint_bounds(study.bounds.triangle_margin)
        # working range the design must serve (const_j at its ends) and the narrower one the ID sees
        self.working, inner = served_ranges(study, ik.position)
        #: the machine the inverse dynamics and the rows see: its stroke chains' ranges narrowed to ``inner``
        self.model = model.with_stroke_ranges(inner)
        check_reference_ranges(study, task, self.model, ik.position, ik.time)
        check_reference_ranges(study, task, self.model, self.B[0] @ self.c_ref.T, self.times, ", its spline fit,")
        self.n_xi = len(model.design_names)
        self.n_c = self.n_joints * self.basis.n
        self.n = self.n_xi + self.n_c
        #: per-sample rows chained to the coefficients on each sample's band of B
        self.chain = SplineChain(self.B, self.n_xi, self.n_joints)
        xi_low, xi_up = study.bounds.xi_low, study.bounds.xi_up
        self.lower = np.concatenate([np.asarray(xi_low) / XI_SCALE, np.full(self.n_c, -np.inf)])
        self.upper = np.concatenate([np.asarray(xi_up) / XI_SCALE, np.full(self.n_c, np.inf)])
        #: rest at both ends: dq = ddq = 0 at t = 0 and at the end, per joint
        self.n_equalities = 4 * self.n_joints
        self.duty_options = duty_options(study, self.emlas, duration)
        self.objective = make_objective(objective or study.energy.objective, self.emlas, self.dt)
        self.layout = BlockLayout(self._build_blocks())
        self.constraint_names = self.layout.names
        #: added to the solver's rows gives the nominal scaled margins (each block owns its clearance)
        self.clearance = self.layout.clearance
        self._id_cache: dict[tuple[bytes, str], InverseDynamics] = {}
        self._eval_cache: dict[bytes, Evaluation] = {}
        self._grad_cache: dict[bytes, tuple[Array, Array]] = {}
        self.jacobian_buffer: Array | None = None  # set: each point's Jacobian overwrites it (solvers.ipopt)
        self.n_evaluations = 0
        self.n_gradients = 0
        self.cost_scale = 1.0
        if cost_scale is None:
            try:
                cost_scale = self.evaluate(self.initial_point(study.initial_lengths)).cost
            except InvalidInputError as error:
                raise start_error(error, "initial_lengths", model) from None
        self.cost_scale = max(abs(float(cost_scale)), 1e-300)  # |f0|: a battery energy may be negative (recovered)

    def fine_times(self) -> Array:
        """The task's re-check grid: ``grid.fine_factor`` times denser than its collocation grid [s]."""
        intervals = len(self.collocation_times) - 1
        return np.linspace(0.0, self.task.reference.duration, self.study.grid.fine_factor * intervals + 1)

    def _build_blocks(self) -> list[ConstraintBlock]:
        """The inequality blocks in row order: the registered ones, then this problem's extra ones."""
        return build_blocks(self) + ([] if self._extra_blocks is None else list(self._extra_blocks(self)))

    # -- variables ---------------------------------------------------------------------------

    @property
    def crane(self) -> Any:
        """The crane description this problem's rows see (crane-only blocks and reports; a machine file has none)."""
        if (crane := getattr(self.model, "crane", None)) is None:
            raise InvalidInputError("machine", self.model.name, "this part of the study needs a crane file (crane:)")
        return crane

    def initial_point(self, lengths: Design, coefficients: Array | None = None) -> Array:
        """Scaled z for link lengths and coefficients (default: the inverse-kinematics fit)."""
        n = self.n_joints
        c = self.c_ref if coefficients is None else np.asarray(coefficients, dtype=float).reshape(n, -1)
        return np.concatenate([lengths.as_array() / XI_SCALE, ((c - self.c_ref) / C_SCALE).ravel()])

    def unpack(self, z: Array) -> tuple[Design, Array]:
        """(Xi, c (n, N)) from scaled z."""
        z = np.asarray(z, dtype=float)
        xi = z[: self.n_xi] * XI_SCALE
        c = self.c_ref + C_SCALE * z[self.n_xi :].reshape(self.n_joints, self.basis.n)
        return self.model.design(xi), c

    # -- evaluation --------------------------------------------------------------------------

    def _id(self, lengths: Design, path: str | None = None) -> InverseDynamics:
        """The inverse dynamics of a design on ``path`` (default: the optimisation's), cached by value."""
        key = (lengths.as_array().tobytes(), path or self.id_path)
        if key not in self._id_cache:
            if len(self._id_cache) > 32:
                self._id_cache.clear()
            self._id_cache[key] = self.model.inverse_dynamics(lengths, key[1])
        return self._id_cache[key]

    def joint_partials(self, lengths: Design, samples: JointSamples) -> Array:
        """dY/d(q, dq, ddq) per sample of a design's inverse dynamics on ``solver.joint_derivatives``' path.

        (K, 3 m, 3 n), :func:`~hiab_sim.study.nlp.id_partials.id_joint_partials` (central differences).
        """
        return id_joint_partials(self._id(lengths, self.q_path), samples, self.fd_step, self.tcp_force)

    def joints(self, c: Array) -> tr.JointTrajectory:
        """Joint samples on this problem's grid for coefficients c (n, N)."""
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
        samples = JointSamples(joints.position, joints.velocity, joints.acceleration)
        act = self._id(lengths)(samples, tcp_force=self.tcp_force)
        tcp = self.kin.samples(joints.position, joints.velocity, joints.acceleration)
        duty = None
        if self.duty_options is not None:
            duty = tuple(
                drive_duty(
                    p, self.times, act.force[:, i], act.velocity[:, i], act.acceleration[:, i], self.duty_options
                )
                for i, p in enumerate(self.emlas)
            )
            power = np.column_stack([d.power for d in duty])
        else:
            power = np.column_stack(
                [
                    electrical_power(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
                    for i, p in enumerate(self.emlas)
                ]
            )
        state = SampleState(lengths, joints, tcp, act, power, duty=duty)
        ev = Evaluation(
            lengths,
            joints,
            tcp,
            act,
            power,
            duty=duty,
            z=z,
            coefficients=c,
            cost=self.objective.value(state),
            constraints=self.layout.values(state),
            equalities=self._equalities(c),
        )
        if len(self._eval_cache) > 8:
            self._eval_cache.clear()
        self._eval_cache[key] = ev
        return ev

    def max_violation(self, z: Array) -> float:
        """Largest violation of any nominal constraint (:meth:`margins`) or bound, in scaled units."""
        ev = self.evaluate(z)
        v = max(0.0, float(-self.margins(z).min()), float(np.abs(ev.equalities).max()))
        zx = np.asarray(z)[: self.n_xi]
        return max(v, float(np.max(self.lower[: self.n_xi] - zx)), float(np.max(zx - self.upper[: self.n_xi])))

    def _equalities(self, c: Array) -> Array:
        return (self._rest_matrix() @ c.T).ravel() / C_SCALE

    def _rest_matrix(self) -> Array:
        ends = np.array([0.0, self.basis.duration])
        return np.vstack([self.basis.matrix(ends, 1), self.basis.matrix(ends, 2)])  # (4, N)

    # -- gradients ---------------------------------------------------------------------------

    def cost_gradient(self, z: Array) -> Array:
        """d(scaled cost)/dz."""
        return self._gradients(z)[0]

    def constraints_jacobian(self, z: Array) -> Array:
        """D g / dz, shape (m, n)."""
        return self._gradients(z)[1]

    def equalities_jacobian(self, z: Array) -> Array:
        """D e / dz (constant), shape (4 n_joints, n)."""
        R = self._rest_matrix()  # (4, N)
        nj = self.n_joints
        jac = np.zeros((4 * nj, self.n))
        for j in range(nj):
            jac[j * 4 : (j + 1) * 4, self.n_xi + j * self.basis.n : self.n_xi + (j + 1) * self.basis.n] = R
        # rows of _equalities are (R @ c.T).ravel(): row r, joint j -> index r * n_joints + j
        order = np.array([r * nj + j for j in range(nj) for r in range(4)])
        out = np.zeros_like(jac)
        out[order] = jac
        return out

    def _to_z(self, block: ConstraintBlock, jac: BlockJacobian, out: Array) -> None:
        """A block's partials w.r.t. q9 and Xi [per m] into its rows ``out`` (rows, n) of D g / dz (zeros on entry).

        Through the spline matrices: a per-sample row sees only the coefficients per joint whose basis
        functions are nonzero at its sample (:class:`~hiab_sim.study.motion.spline_chain.SplineChain`).
        """
        K, nj = len(self.times), self.n_joints
        rows = out.shape[0]
        if isinstance(jac, SampleRows):
            self.chain.write_sample_rows(jac.dq, out, C_SCALE)  # the block's rows: contiguous rows of D g / dz
            if jac.dxi is not None:
                out[:, : self.n_xi] = (jac.dxi * XI_SCALE).reshape(rows, self.n_xi)
        else:
            if jac.dq is not None:
                dc = np.einsum("mkoj,okn->mjn", jac.dq.reshape(rows, K, 3, nj), self.B) * C_SCALE
                out[:, self.n_xi :] = dc.reshape(rows, self.n_c)
            if jac.dxi is not None:
                out[:, : self.n_xi] = jac.dxi * XI_SCALE

    def _gradients(self, z: Array) -> tuple[Array, Array]:
        z = np.array(z, dtype=float)
        key = z.tobytes()
        if key in self._grad_cache:
            return self._grad_cache[key]
        self.n_gradients += 1
        ev = self.evaluate(z)
        samples = JointSamples(ev.joints.position, ev.joints.velocity, ev.joints.acceleration)
        partials = SamplePartials(
            lambda: self.joint_partials(ev.lengths, samples),
            lambda: self.model.design_partials(ev.lengths, samples, self.xi_path, self.fd_step, self.tcp_force),
        )
        if self.jacobian_buffer is not None:  # it holds one point's Jacobian: the one written next
            self._grad_cache.clear()
        jac = self.layout.jacobian(ev, partials, self._to_z, self.n, self.jacobian_buffer)
        dcost_q, dcost_xi = self.objective.gradient(ev, partials)
        K = len(self.times)
        grad_c = np.einsum("koj,okn->jn", dcost_q.reshape(K, 3, self.n_joints), self.B).ravel() * C_SCALE
        grad = np.concatenate([dcost_xi * XI_SCALE, grad_c]) / self.cost_scale
        if len(self._grad_cache) > 4:
            self._grad_cache.clear()
        self._grad_cache[key] = (grad, jac)
        return grad, jac

"""The NLP's constraint blocks (seed eqs. ``const_b``..``const_k``), each owning its rows and partials.

All rows are scaled to O(1) and written g >= 0 (see :mod:`hiab_sim.study.nlp.interface` for the interface):

* :class:`TrackingBand` (``const_b``..``const_d``): |r - r_ref| <= band for r = (x_tcp, y_tcp, xt2)
  and one time-derivative order, at every sample;
* :class:`EnvelopeMargins` (``const_e``, ``const_f``): the EMLA envelope margins (peak torque,
  rated speed, voltage) >= ``margin``;
* :class:`StrokeLimits` (``const_j``): 0 <= x <= Lc and x <= stroke at every sample;
* :class:`JointLimits` (``const_h`` with ``const_k``): theta within the crane's joint range and
  the hinge-angle margin (linear in the joint samples);
* :class:`JointVelocityLimits` (``const_i``): |dtheta| <= the joint velocity limit;
* :class:`WorkingRange` (``const_j`` at the ends of the working range, Xi only), with the
  optimiser's clearance;
* :class:`ObjectiveBound`: any objective held below a bound, (bound - f) / scale >= 0 (the
  epsilon constraint of a Pareto front).

The stroke trigonometry is :func:`hiab_sim.crane.mechanism.joint_to_stroke` and its partials
:func:`hiab_sim.crane.mechanism.joint_to_stroke_partials`.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence

import numpy as np

from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ClosedChain, LinkLengths
from hiab_sim.crane.names import ACTUATOR_NAMES, JOINT_NAMES
from hiab_sim.emla import ENVELOPE_LIMIT_NAMES, EmlaSet, envelope_margin_partials, envelope_margins
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.nlp.interface import (
    N_Q,
    N_XI,
    Array,
    ConstraintBlock,
    DenseRows,
    Objective,
    PerSampleBlock,
    Relaxation,
    SamplePartials,
    SampleRows,
    SampleState,
)

#: Scale of the stroke constraints [m per unit].
STROKE_SCALE = 0.1
#: Tracked coordinates r = (x_tcp [m], y_tcp [m], xt2 [m]).
TRACKED = ("x_tcp", "y_tcp", "xt2")
#: Rows of one chain's stroke limits (const_j), scaled by 1 / STROKE_SCALE.
STROKE_ROWS = ("x >= 0", "x <= Lc", "x <= stroke")
#: Unit of one step of relaxation of a tracking band, by derivative order.
_TRACKING_UNITS = {"position": "mm", "velocity": "mm/s", "acceleration": "mm/s^2"}
#: Per-sample row pairs (i, i + 3) of a block whose first three rows bound three quantities from one
#: side and last three from the other (:attr:`hiab_sim.study.nlp.interface.PerSampleBlock.pairs`).
OPPOSITE_ROWS = ((0, 3), (1, 4), (2, 5))


class TrackingBand(PerSampleBlock):
    """|r^(order) - r_ref^(order)| <= band * fraction at every sample (const_b..const_d).

    Args:
        order: ``position``, ``velocity`` or ``acceleration``.
        times: sample times [s], (K,).
        target: the reference's r^(order), (K, 3) [m, m/s or m/s^2].
        band: the tolerance [same unit]; ``fraction`` tightens it on the optimiser's grid.

    """

    def __init__(self, order: str, times: Array, target: Array, band: float, fraction: float) -> None:
        self.name = f"tracking.{order}"
        self.order = order
        self.times = times
        self.target = target
        self.band = band
        self.width = band * fraction
        self.sample_rows = (*(f"{c} <= band" for c in TRACKED), *(f"{c} >= -band" for c in TRACKED))
        self.pairs = OPPOSITE_ROWS  # (1 - e) + (1 + e) = 2

    def values(self, state: SampleState) -> Array:
        """1 - e and 1 + e per sample, e = (r - r_ref) / width."""
        err = (getattr(state.tcp, self.order) - self.target) / self.width
        return np.concatenate([1.0 - err, 1.0 + err], axis=1).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """-dr/dq9 / width and +dr/dq9 / width (the TCP kinematics' exact partials)."""
        d = getattr(state.tcp, f"d_{self.order}")
        return SampleRows(np.concatenate([-d / self.width, d / self.width], axis=1))

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm (mm/s, mm/s^2) of the band: the row 1 - e / (b phi) at an active sample moves by 1e-3 / b."""
        return Relaxation.uniform(_TRACKING_UNITS[self.order], 1e-3 / self.band, len(values))

    def limit_name(self, row: str) -> str:
        """``tracking.<order>.<coordinate>``: both sides of one coordinate's band at every sample."""
        return super().limit_name(row).rsplit(" ", 2)[0]


class EnvelopeMargins(PerSampleBlock):
    """(g - margin) / (1 - margin) >= 0 for each EMLA's envelope margins g (const_e, const_f).

    Rows per sample: actuator-major, then :data:`hiab_sim.emla.ENVELOPE_LIMIT_NAMES`.
    """

    def __init__(self, times: Array, emlas: EmlaSet, margin: float) -> None:
        self.name = "envelope"
        self.times = times
        self.emlas = emlas
        self.margin = margin
        self.sample_rows = tuple(f"{a}.{lim}" for a in ACTUATOR_NAMES for lim in ENVELOPE_LIMIT_NAMES)

    def values(self, state: SampleState) -> Array:
        """Scaled margins per sample, (K * 9,)."""
        act = state.actuators
        env = np.stack(
            [
                envelope_margins(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
                for i, p in enumerate(self.emlas)
            ],
            axis=1,
        )  # (3 limits, 3 actuators, K)
        env = (env - self.margin) / (1.0 - self.margin)
        return np.transpose(env, (2, 1, 0)).reshape(len(self.times), 9).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """Analytic EMLA partials w.r.t. (f, v, a), chained through the inverse dynamics' partials."""
        act = state.actuators
        K = len(self.times)
        dG = np.zeros((K, 3, 3, 9))  # margins (actuator, limit) w.r.t. Y = (f0 f1 f2 v0 v1 v2 a0 a1 a2)
        for i, p in enumerate(self.emlas):
            gf, gv, ga = envelope_margin_partials(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
            dG[:, i, :, i], dG[:, i, :, 3 + i], dG[:, i, :, 6 + i] = gf.T, gv.T, ga.T
        dGY = dG.reshape(K, 9, 9) / (1.0 - self.margin)
        return SampleRows(np.einsum("kmy,kyq->kmq", dGY, partials.id_q), np.einsum("kmy,kyx->kmx", dGY, partials.id_xi))

    def relaxation(self, values: Array) -> Relaxation:
        """Per % of an EMLA limit: g = 1 - (y / y_max)^2 moves by (1 - g)(1 - 1 / 1.01^2), scaled by 1 / (1 - m)."""
        m = self.margin
        g = np.asarray(values, dtype=float) * (1.0 - m) + m
        return Relaxation(("%",) * len(g), (1.0 - g) * (1.0 - 1.0 / 1.01**2) / (1.0 - m))


def stroke_margins(chains: Sequence[ClosedChain], lengths: LinkLengths, theta: Array) -> Array:
    """const_j per chain at joint angles theta (K, >= 2): x, Lc - x, stroke - x, (K, 6) scaled."""
    cols = []
    for j, chain in enumerate(chains):
        xi = getattr(lengths, chain.name)
        x = mechanism.joint_to_stroke(chain, xi, theta[:, j])
        cols += [x, xi.Lc - x, chain.stroke - x]
    return np.column_stack(cols) / STROKE_SCALE


def stroke_margin_partials(chains: Sequence[ClosedChain], lengths: LinkLengths, theta: Array) -> tuple[Array, Array]:
    """Partials of :func:`stroke_margins` w.r.t. q9 (K, 6, 9) and Xi (K, 6, 6) [per m]."""
    K = theta.shape[0]
    dq = np.zeros((K, 6, N_Q))
    dxi = np.zeros((K, 6, N_XI))
    for j, chain in enumerate(chains):
        dx_dtheta, dx_dxi = mechanism.joint_to_stroke_partials(chain, getattr(lengths, chain.name), theta[:, j])
        r = 3 * j
        dq[:, r, j], dq[:, r + 1, j], dq[:, r + 2, j] = dx_dtheta, -dx_dtheta, -dx_dtheta
        cols = slice(3 * j, 3 * j + 3)
        dxi[:, r, cols] = dx_dxi
        dxi[:, r + 1, cols] = -dx_dxi
        dxi[:, r + 1, 3 * j + 2] += 1.0  # d(Lc)/dLc
        dxi[:, r + 2, cols] = -dx_dxi
    return dq / STROKE_SCALE, dxi / STROKE_SCALE


class StrokeLimits(PerSampleBlock):
    """0 <= x <= Lc and x <= stroke for lift and tilt at every sample (const_j)."""

    def __init__(self, times: Array, chains: Sequence[ClosedChain]) -> None:
        self.name = "stroke"
        self.times = times
        self.chains = tuple(chains)
        self.sample_rows = tuple(f"{c.name}.{w}" for c in self.chains for w in STROKE_ROWS)
        # x + (stroke - x) = stroke; x + (Lc - x) = Lc depends on Xi and is not a pair
        self.pairs = tuple((3 * j, 3 * j + 2) for j in range(len(self.chains)))

    def values(self, state: SampleState) -> Array:
        """Scaled stroke margins per sample, (K * 6,)."""
        return stroke_margins(self.chains, state.lengths, state.joints.position).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """Exact partials of the chain trigonometry (eq. qus_a)."""
        return SampleRows(*stroke_margin_partials(self.chains, state.lengths, state.joints.position))

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm of stroke: 1e-3 / STROKE_SCALE."""
        return Relaxation.uniform("mm", 1e-3 / STROKE_SCALE, len(values))


class JointLimits(PerSampleBlock):
    """theta - low >= 0 and up - theta >= 0 for (theta1, theta2, xt2) at every sample (const_h, const_k)."""

    def __init__(self, times: Array, low: Array, up: Array) -> None:
        self.name = "joint"
        self.times = times
        self.low = low
        self.up = up
        self.sample_rows = (*(f"{j} >= low" for j in JOINT_NAMES), *(f"{j} <= up" for j in JOINT_NAMES))
        self.pairs = OPPOSITE_ROWS  # (theta - low) + (up - theta) = up - low

    def values(self, state: SampleState) -> Array:
        """Distances to the joint bounds [rad, rad, m], (K * 6,)."""
        th = state.joints.position
        return np.concatenate([th - self.low, self.up - th], axis=1).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """+-1 on the joint positions."""
        jq = np.zeros((len(self.times), 6, N_Q))
        eye = np.eye(3)
        jq[:, :3, :3], jq[:, 3:, :3] = eye, -eye
        return SampleRows(jq)

    def relaxation(self, values: Array) -> Relaxation:
        """Per mrad of an angle's limit, per mm of the telescope's: 1e-3 (the rows are rad and m)."""
        per_sample = ("mrad", "mrad", "mm") * 2  # rows (theta1, theta2, xt2) >= low, then <= up
        return Relaxation(per_sample * (len(values) // len(per_sample)), np.full(len(values), 1e-3))


class JointVelocityLimits(PerSampleBlock):
    """|dtheta| <= limit for (theta1, theta2, xt2) at every sample, scaled by the limit (const_i)."""

    def __init__(self, times: Array, limit: Array) -> None:
        self.name = "joint_velocity"
        self.times = times
        self.limit = np.asarray(limit, dtype=float)
        self.sample_rows = (*(f"{j} <= limit" for j in JOINT_NAMES), *(f"{j} >= -limit" for j in JOINT_NAMES))
        self.pairs = OPPOSITE_ROWS  # (1 - dtheta / limit) + (1 + dtheta / limit) = 2

    def values(self, state: SampleState) -> Array:
        """1 - dtheta / limit and 1 + dtheta / limit, (K * 6,)."""
        dth = state.joints.velocity / self.limit
        return np.concatenate([1.0 - dth, 1.0 + dth], axis=1).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """-+1 / limit on the joint velocities."""
        vq = np.zeros((len(self.times), 6, N_Q))
        vq[:, :3, 3:6], vq[:, 3:, 3:6] = -np.diag(1.0 / self.limit), np.diag(1.0 / self.limit)
        return SampleRows(vq)

    def relaxation(self, values: Array) -> Relaxation:
        """Per % of the velocity limit: the row 1 - dtheta / limit moves by ~0.01."""
        return Relaxation.uniform("%", 0.01, len(values))


class WorkingRange(ConstraintBlock):
    """const_j at both ends of the working joint range (Xi only), held with a clearance by the optimiser.

    Args:
        chains: lift and tilt.
        working: the joint range (low, high) [rad] each chain must serve.
        clearance: scaled margin the solver's rows keep (``WORKING_CLEARANCE / STROKE_SCALE`` on the
            optimiser's grid, 0 for the nominal re-check); :meth:`clearance` returns it, so the
            nominal margins are the solver's rows plus it.

    """

    def __init__(self, chains: Sequence[ClosedChain], working: Sequence[tuple[float, float]], clearance: float) -> None:
        self.name = "working_range"
        self.chains = tuple(chains)
        self.working = tuple(working)
        self._clearance = clearance
        # (2 ends, >= 2 joints): theta at the low end, then at the high end
        self.theta = np.array([[w[0] for w in self.working], [w[1] for w in self.working]])

    def row_names(self) -> list[str]:
        """``working_range.<chain>.<row> at the low|up end``."""
        stroke_names = [f"{c.name}.{w}" for c in self.chains for w in STROKE_ROWS]
        return [f"{self.name}.{s} at the {end} end" for end in ("low", "up") for s in stroke_names]

    def values(self, state: SampleState) -> Array:
        """Scaled stroke margins at both ends less the clearance, (12,)."""
        return stroke_margins(self.chains, state.lengths, self.theta).ravel() - self._clearance

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """Partials w.r.t. Xi only, (12, 6) [per m]."""
        return DenseRows(dxi=stroke_margin_partials(self.chains, state.lengths, self.theta)[1].reshape(-1, N_XI))

    def clearance(self) -> float:
        """The optimiser's clearance (scaled)."""
        return self._clearance

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm of stroke: 1e-3 / STROKE_SCALE."""
        return Relaxation.uniform("mm", 1e-3 / STROKE_SCALE, len(values))

    def shared_key(self) -> Hashable:
        """Rows of Xi only: the same for every task with the same chains, range and clearance."""
        return (self.name, repr(self.chains), self.theta.tobytes(), self._clearance)


class ObjectiveBound(ConstraintBlock):
    """(bound - f(state)) / scale >= 0 for an objective f: an epsilon constraint (one row, all samples).

    Args:
        objective: the criterion f (:class:`hiab_sim.study.nlp.interface.Objective`).
        bound: epsilon [f's unit].
        scale: divisor that makes the row O(1) [f's unit], > 0.

    """

    def __init__(self, objective: Objective, bound: float, scale: float) -> None:
        if not scale > 0.0:
            raise InvalidInputError(f"bound.{objective.name}.scale", scale, "must be > 0", objective.unit)
        self.name = f"bound.{objective.name}"
        self.objective = objective
        self.bound = bound
        self.scale = scale

    def row_names(self) -> list[str]:
        """``bound.<objective> <= <bound> <unit>``."""
        return [f"{self.name} <= {self.bound:.6g} {self.objective.unit}"]

    def values(self, state: SampleState) -> Array:
        """(bound - f) / scale, (1,)."""
        return np.array([(self.bound - self.objective.value(state)) / self.scale])

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """-(df/dq9, df/dXi) / scale."""
        dq, dxi = self.objective.gradient(state, partials)
        return DenseRows(dq=-dq[None] / self.scale, dxi=-dxi[None] / self.scale)

    def relaxation(self, values: Array) -> Relaxation:
        """Per unit of the objective's bound: 1 / scale."""
        return Relaxation.uniform(self.objective.unit, 1.0 / self.scale, len(values))

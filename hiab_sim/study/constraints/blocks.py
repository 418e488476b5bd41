"""The NLP's constraint blocks (seed eqs. ``const_b``..``const_k``), each owning its rows and partials.

All rows are scaled to O(1) and written g >= 0 (see :mod:`hiab_sim.study.nlp.interface` for the interface):

* :class:`TrackingBand` (``const_b``..``const_d``): |r - r_ref| <= band for the machine's tracked
  coordinates r (the crane's (x_tcp, y_tcp, xt2)) and one time-derivative order, at every sample;
* :class:`EnvelopeMargins` (``const_e``, ``const_f``): the EMLA envelope margins (peak torque,
  rated speed, voltage) >= ``margin``;
* :class:`StrokeLimits` (``const_j``): 0 <= x <= Lc and x <= stroke at every sample;
* :class:`JointLimits` (``const_h`` with ``const_k``): theta within the machine's joint range and
  the hinge-angle margin (linear in the joint samples);
* :class:`JointVelocityLimits` (``const_i``): |dtheta| <= the joint velocity limit;
* :class:`WorkingRange` (``const_j`` at the ends of the working range, Xi only), with the
  optimiser's clearance;
* :class:`ObjectiveBound`: any objective held below a bound, (bound - f) / scale >= 0 (the
  epsilon constraint of a Pareto front).

The stroke x(q, Xi) and its partials are the machine's
(:meth:`hiab_sim.study.machines.protocol.StudyMachine.stroke_margins`); names of joints, actuators,
chains and tracked coordinates come from the machine. With n joints a sample's q9 has 3 n entries.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla import ENVELOPE_LIMIT_NAMES, EmlaSet, envelope_margin_partials, envelope_margins
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.machines.protocol import Design, StudyMachine
from hiab_sim.study.nlp.interface import (
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
#: Rows of one chain's stroke limits (const_j), scaled by 1 / STROKE_SCALE.
STROKE_ROWS = ("x >= 0", "x <= Lc", "x <= stroke")
#: Unit of one step of relaxation of a tracking band, by derivative order.
_TRACKING_UNITS = {"position": "mm", "velocity": "mm/s", "acceleration": "mm/s^2"}


def opposite_rows(n: int) -> tuple[tuple[int, int], ...]:
    """Per-sample row pairs (i, i + n) of a block bounding n quantities from both sides.

    The first n rows bound them from one side, the last n from the other
    (:attr:`hiab_sim.study.nlp.interface.PerSampleBlock.pairs`).
    """
    return tuple((i, i + n) for i in range(n))


class TrackingBand(PerSampleBlock):
    """|r^(order) - r_ref^(order)| <= band * fraction at every sample (const_b..const_d).

    Args:
        order: ``position``, ``velocity`` or ``acceleration``.
        times: sample times [s], (K,).
        target: the reference's r^(order), (K, n) [m, m/s or m/s^2; rad for an attitude].
        band: the tolerance [same unit]; ``fraction`` tightens it on the optimiser's grid.
        tracked: the names of the tracked coordinates (n,); ``units`` their units (m or rad; an angle's band
            is the same number in rad: 1e-3 m -> 1 mrad).

    """

    def __init__(
        self,
        order: str,
        times: Array,
        target: Array,
        band: float,
        fraction: float,
        tracked: tuple[str, ...],
        units: tuple[str, ...] | None = None,
    ) -> None:
        self.units = units if units is not None else ("m",) * len(tracked)
        self.name = f"tracking.{order}"
        self.order = order
        self.times = times
        self.target = target
        self.band = band
        self.width = band * fraction
        self.sample_rows = (*(f"{c} <= band" for c in tracked), *(f"{c} >= -band" for c in tracked))
        self.pairs = opposite_rows(len(tracked))  # (1 - e) + (1 + e) = 2

    def values(self, state: SampleState) -> Array:
        """1 - e and 1 + e per sample, e = (r - r_ref) / width."""
        err = (getattr(state.tcp, self.order) - self.target) / self.width
        return np.concatenate([1.0 - err, 1.0 + err], axis=1).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """-dr/dq9 / width and +dr/dq9 / width (the TCP kinematics' exact partials)."""
        d = getattr(state.tcp, f"d_{self.order}")
        return SampleRows(np.concatenate([-d / self.width, d / self.width], axis=1))

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm or mrad (/s, /s^2) of the band: the row 1 - e / (b phi) at an active sample moves by 1e-3 / b."""
        suffix = _TRACKING_UNITS[self.order][2:]
        per_sample = tuple(("mrad" if u == "rad" else "mm") + suffix for u in self.units) * 2
        return Relaxation(per_sample * (len(values) // len(per_sample)), np.full(len(values), 1e-3 / self.band))

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
        self.sample_rows = tuple(f"{a}.{lim}" for a in emlas.names for lim in ENVELOPE_LIMIT_NAMES)

    def values(self, state: SampleState) -> Array:
        """Scaled margins per sample, (K * 3 n,)."""
        act = state.actuators
        env = np.stack(
            [
                envelope_margins(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
                for i, p in enumerate(self.emlas)
            ],
            axis=1,
        )  # (3 limits, n actuators, K)
        env = (env - self.margin) / (1.0 - self.margin)
        return np.transpose(env, (2, 1, 0)).reshape(len(self.times), len(self.sample_rows)).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """Analytic EMLA partials w.r.t. (f, v, a), chained through the inverse dynamics' partials."""
        act = state.actuators
        K, n = len(self.times), len(self.emlas)
        lim = len(ENVELOPE_LIMIT_NAMES)
        dG = np.zeros((K, n, lim, 3 * n))  # margins (actuator, limit) w.r.t. Y = (f_0..f_n-1, v_.., a_..)
        for i, p in enumerate(self.emlas):
            gf, gv, ga = envelope_margin_partials(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
            dG[:, i, :, i], dG[:, i, :, n + i], dG[:, i, :, 2 * n + i] = gf.T, gv.T, ga.T
        dGY = dG.reshape(K, n * lim, 3 * n) / (1.0 - self.margin)
        return SampleRows(np.einsum("kmy,kyq->kmq", dGY, partials.id_q), np.einsum("kmy,kyx->kmx", dGY, partials.id_xi))

    def relaxation(self, values: Array) -> Relaxation:
        """Per % of an EMLA limit: g = 1 - (y / y_max)^2 moves by (1 - g)(1 - 1 / 1.01^2), scaled by 1 / (1 - m)."""
        m = self.margin
        g = np.asarray(values, dtype=float) * (1.0 - m) + m
        return Relaxation(("%",) * len(g), (1.0 - g) * (1.0 - 1.0 / 1.01**2) / (1.0 - m))


def stroke_margins(model: StudyMachine, design: Design, q: Array) -> Array:
    """const_j per stroke chain at joint positions q (K, n): x, Lc - x, stroke - x, (K, 3 m) scaled."""
    return model.stroke_margins(design, q) / STROKE_SCALE


def stroke_margin_partials(model: StudyMachine, design: Design, q: Array) -> tuple[Array, Array]:
    """Partials of :func:`stroke_margins` w.r.t. q9 (K, 3 m, 3 n) and Xi (K, 3 m, n_xi) [per m]."""
    dq_pos, dxi = model.stroke_margin_partials(design, q)
    K, rows, n = dq_pos.shape
    dq = np.zeros((K, rows, 3 * n))
    dq[:, :, :n] = dq_pos
    return dq / STROKE_SCALE, dxi / STROKE_SCALE


class StrokeLimits(PerSampleBlock):
    """0 <= x <= Lc and x <= stroke for lift and tilt at every sample (const_j)."""

    def __init__(self, times: Array, model: StudyMachine) -> None:
        self.name = "stroke"
        self.times = times
        self.model = model
        self.sample_rows = tuple(f"{c}.{w}" for c in model.stroke_chains for w in STROKE_ROWS)
        # x + (stroke - x) = stroke; x + (Lc - x) = Lc depends on Xi and is not a pair
        self.pairs = tuple((3 * j, 3 * j + 2) for j in range(len(model.stroke_chains)))

    def values(self, state: SampleState) -> Array:
        """Scaled stroke margins per sample, (K * 3 m,)."""
        return stroke_margins(self.model, state.lengths, state.joints.position).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """Exact partials of the chain trigonometry (eq. qus_a)."""
        return SampleRows(*stroke_margin_partials(self.model, state.lengths, state.joints.position))

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm of stroke: 1e-3 / STROKE_SCALE."""
        return Relaxation.uniform("mm", 1e-3 / STROKE_SCALE, len(values))


class JointLimits(PerSampleBlock):
    """q - low >= 0 and up - q >= 0 for every joint at every sample (const_h, const_k).

    Args:
        times: sample times [s].
        low, up: the joint bounds (n,) [rad or m].
        joints: the joints' names (n,) and ``units`` (``rad`` or ``m`` each).

    """

    def __init__(self, times: Array, low: Array, up: Array, joints: tuple[str, ...], units: tuple[str, ...]) -> None:
        self.name = "joint"
        self.times = times
        self.low = low
        self.up = up
        self.units = units
        self.sample_rows = (*(f"{j} >= low" for j in joints), *(f"{j} <= up" for j in joints))
        self.pairs = opposite_rows(len(joints))  # (theta - low) + (up - theta) = up - low

    def values(self, state: SampleState) -> Array:
        """Distances to the joint bounds [rad or m], (K * 2 n,)."""
        th = state.joints.position
        return np.concatenate([th - self.low, self.up - th], axis=1).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """+-1 on the joint positions."""
        n = len(self.low)
        jq = np.zeros((len(self.times), 2 * n, 3 * n))
        eye = np.eye(n)
        jq[:, :n, :n], jq[:, n:, :n] = eye, -eye
        return SampleRows(jq)

    def relaxation(self, values: Array) -> Relaxation:
        """Per mrad of an angle's limit, per mm of a prismatic joint's: 1e-3 (the rows are rad and m)."""
        milli = {"rad": "mrad", "m": "mm"}
        per_sample = tuple(milli[u] for u in self.units) * 2  # rows q >= low, then q <= up
        return Relaxation(per_sample * (len(values) // len(per_sample)), np.full(len(values), 1e-3))


class JointVelocityLimits(PerSampleBlock):
    """|dq| <= limit for every joint at every sample, scaled by the limit (const_i)."""

    def __init__(self, times: Array, limit: Array, joints: tuple[str, ...]) -> None:
        self.name = "joint_velocity"
        self.times = times
        self.limit = np.asarray(limit, dtype=float)
        self.sample_rows = (*(f"{j} <= limit" for j in joints), *(f"{j} >= -limit" for j in joints))
        self.pairs = opposite_rows(len(joints))  # (1 - dtheta / limit) + (1 + dtheta / limit) = 2

    def values(self, state: SampleState) -> Array:
        """1 - dq / limit and 1 + dq / limit, (K * 2 n,)."""
        dth = state.joints.velocity / self.limit
        return np.concatenate([1.0 - dth, 1.0 + dth], axis=1).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """-+1 / limit on the joint velocities."""
        n = len(self.limit)
        vq = np.zeros((len(self.times), 2 * n, 3 * n))
        vq[:, :n, n : 2 * n], vq[:, n:, n : 2 * n] = -np.diag(1.0 / self.limit), np.diag(1.0 / self.limit)
        return SampleRows(vq)

    def relaxation(self, values: Array) -> Relaxation:
        """Per % of the velocity limit: the row 1 - dtheta / limit moves by ~0.01."""
        return Relaxation.uniform("%", 0.01, len(values))


class WorkingRange(ConstraintBlock):
    """const_j at both ends of the working joint range (Xi only), held with a clearance by the optimiser.

    Args:
        model: the machine (its stroke chains and their joints).
        working: the joint range (low, high) [rad] each stroke chain's joint must serve.
        clearance: scaled margin the solver's rows keep (``WORKING_CLEARANCE / STROKE_SCALE`` on the
            optimiser's grid, 0 for the nominal re-check); :meth:`clearance` returns it, so the
            nominal margins are the solver's rows plus it.

    """

    def __init__(self, model: StudyMachine, working: Sequence[tuple[float, float]], clearance: float) -> None:
        self.name = "working_range"
        self.model = model
        self.working = tuple(working)
        self._clearance = clearance
        # (2 ends, n joints): q at the low end, then at the high end; a joint without a stroke chain
        # sits at the middle of its range (its column is not read)
        ends = np.array([[0.5 * (lo + hi)] * 2 for lo, hi in model.joint_ranges()]).T
        for j, (lo, hi) in zip(model.stroke_joints, self.working, strict=True):
            ends[0, j], ends[1, j] = lo, hi
        self.theta = ends

    def row_names(self) -> list[str]:
        """``working_range.<chain>.<row> at the low|up end``."""
        stroke_names = [f"{c}.{w}" for c in self.model.stroke_chains for w in STROKE_ROWS]
        return [f"{self.name}.{s} at the {end} end" for end in ("low", "up") for s in stroke_names]

    def values(self, state: SampleState) -> Array:
        """Scaled stroke margins at both ends less the clearance, (2 * 3 m,)."""
        return stroke_margins(self.model, state.lengths, self.theta).ravel() - self._clearance

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """Partials w.r.t. Xi only, (2 * 3 m, n_xi) [per m]."""
        dxi = stroke_margin_partials(self.model, state.lengths, self.theta)[1]
        return DenseRows(dxi=dxi.reshape(-1, dxi.shape[-1]))

    def clearance(self) -> float:
        """The optimiser's clearance (scaled)."""
        return self._clearance

    def relaxation(self, values: Array) -> Relaxation:
        """Per mm of stroke: 1e-3 / STROKE_SCALE."""
        return Relaxation.uniform("mm", 1e-3 / STROKE_SCALE, len(values))

    def shared_key(self) -> Hashable:
        """Rows of Xi only: the same for every task with the same chains, range and clearance."""
        return (self.name, repr(self.model), self.theta.tobytes(), self._clearance)


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

"""The building blocks of the NLP: what a constraint block or an objective sees, returns and owns.

A point z of a task's NLP is turned by :class:`hiab_sim.study.nlp.task_problem.TaskProblem` into a
:class:`SampleState` (link lengths Xi, joint samples q9 = (theta, dtheta, ddtheta) per sample,
TCP samples, actuator samples [f_x, v_x, a_x] from the inverse dynamics, EMLA electrical power).
Blocks and objectives read only that state and, for gradients, :class:`SamplePartials` (the
inverse dynamics' partials, computed at most once per point and only when asked for). They
return partials w.r.t. the per-sample q9 and the unscaled Xi [per m]; the problem chains them
through the B-spline matrices and the variable scaling to z, so no block knows the layout of z.

A constraint block (:class:`ConstraintBlock`) owns its ``name``, its row names, its values
(scaled to O(1), feasible where >= 0), its partials, and an optional clearance (a margin the
optimiser keeps that is not part of the nominal constraint). Its Jacobian is either
:class:`SampleRows` (row k * r + i depends on sample k only: tracking, envelope, strokes) or
:class:`DenseRows` (a row depends on many samples, e.g. an RMS-torque integral, or on Xi only,
e.g. the working range). :class:`BlockLayout` assembles row names, row slices, clearances and
the Jacobian of one list of blocks, and splits any row vector (margins, multipliers) by block.

An objective (:class:`Objective`) returns its value [its unit] and gradient w.r.t. q9 (K, 3 n)
and Xi (n_xi,); the problem divides both by its ``cost_scale``.

Extending (one module and its registration each, docs/extending.md):

- a block: subclass :class:`PerSampleBlock` (same rows at every sample, return :class:`SampleRows`)
  or :class:`ConstraintBlock` (return :class:`DenseRows`), give its rows' unit
  (:meth:`ConstraintBlock.relaxation`) and register a factory with
  :func:`hiab_sim.study.constraints.block_registry.register_block`. An integral row (RMS torque over the duty, a thermal
  steady state) returns ``DenseRows(dq=(m, K, 3 n), dxi=(m, n_xi))``; a row of Xi only (working
  range, mounting-space polygons) ``DenseRows(dxi=...)``; an epsilon constraint on any objective
  is :class:`hiab_sim.study.constraints.blocks.ObjectiveBound`.
- an objective: a class with ``name``, ``unit``, ``value`` and ``gradient`` registered with
  :func:`hiab_sim.study.nlp.objectives.register_objective` (:data:`~hiab_sim.study.nlp.objectives.OBJECTIVES`).
- several tasks: each task's blocks read that task's state; :class:`hiab_sim.study.nlp.problem.StudyProblem`
  stacks them, holding a block of Xi only once per :meth:`ConstraintBlock.shared_key`.
- multipliers or margins by name: :meth:`BlockLayout.split` and :meth:`BlockLayout.named` cut any
  row vector into blocks and rows.
"""

from __future__ import annotations

import re
from abc import ABC, abstractmethod
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Protocol

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.dynamics.samples import ActuatorSamples
from hiab_sim.emla.duty_energy import DriveDuty
from hiab_sim.study.machines.protocol import Design
from hiab_sim.study.motion import trajectory as tr

#: The XS 031 crane's per-sample joint quantities q9 = (theta 0-2, dtheta 3-5, ddtheta 6-8): the
#: crane-only blocks (structure, buildable design) use it; every other block reads n from its state
#: (a machine of n joints has 3 n per sample: q, dq, ddq).
N_Q = 9
#: The XS 031 crane's link-length variables Xi = (lift L, Lc0, Lc, tilt L, Lc0, Lc) [m] (crane-only blocks).
N_XI = 6


@dataclass(frozen=True)
class SampleState:
    """What blocks and objectives read at one point (SI units, K samples at ``joints.time``)."""

    lengths: Design  # Xi (the crane's LinkLengths, a machine's design values)
    joints: tr.JointTrajectory  # (K, n) each
    tcp: tr.TcpSamples  # tracked coordinates (K, n) each, partials (K, n, 3 n)
    actuators: ActuatorSamples  # (K, n) each
    power: Array  # (K, n) EMLA electrical power [W] (at the winding temperature when ``duty`` is set)
    #: each EMLA over the study's duty period (hot windings, the rest's hold), or None: the paper's
    #: per-sample model with R_s at its data-sheet value and a free rest (:mod:`hiab_sim.emla.duty_energy`)
    duty: tuple[DriveDuty, ...] | None = field(default=None, kw_only=True)


class SamplePartials:
    """Inverse-dynamics partials at one point, each computed on first use and then kept.

    ``id_q``: d(f, v, a)/d(q9) per sample, (K, 3 n outputs, 3 n inputs); outputs in the order
    (f of each actuator, then v, then a). ``id_xi``: d(f, v, a)/dXi per sample, (K, 3 n, n_xi) [per m].
    """

    def __init__(self, id_q: Callable[[], Array], id_xi: Callable[[], Array]) -> None:
        self._id_q = id_q
        self._id_xi = id_xi

    @cached_property
    def id_q(self) -> Array:
        """d(f, v, a)/d(theta, dtheta, ddtheta), (K, 3 n, 3 n)."""
        return self._id_q()

    @cached_property
    def id_xi(self) -> Array:
        """d(f, v, a)/dXi, (K, 3 n, n_xi) [per m]."""
        return self._id_xi()


@dataclass(frozen=True)
class SampleRows:
    """Jacobian of r rows per sample (row k * r + i depends on sample k only).

    ``dq``: (K, r, 3 n) w.r.t. that sample's q9; ``dxi``: (K, r, n_xi) w.r.t. Xi [per m], None if zero.
    """

    dq: Array
    dxi: Array | None = None


@dataclass(frozen=True)
class DenseRows:
    """Jacobian of m rows that may depend on every sample (integrals) or on Xi only.

    ``dq``: (m, K, 3 n) w.r.t. every sample's q9, None if zero; ``dxi``: (m, n_xi) [per m], None if zero.
    """

    dq: Array | None = None
    dxi: Array | None = None


BlockJacobian = SampleRows | DenseRows

#: A row name's sample suffix (`` at t=<t> s``): rows of one limit at different samples share the rest.
_SAMPLE = re.compile(r" at t=[-0-9.e+]+ s$")


@dataclass(frozen=True)
class Relaxation:
    """What relaxing each row's physical limit by one unit does to the scaled row (for the sensitivities).

    ``units``: per row, the physical unit of one step of relaxation (``mm`` of a band or a stroke,
    ``%`` of an EMLA limit, ``K`` of a temperature limit, an objective's unit for an epsilon row);
    ``per_unit``: per row, d(scaled row)/d(one such unit) >= 0 at the row's current value. The
    objective's decrease per unit of relaxation is then multiplier x ``per_unit`` x the objective's scale.
    """

    units: tuple[str, ...]
    per_unit: Array

    @classmethod
    def uniform(cls, unit: str, per_unit: float, rows: int) -> Relaxation:
        """Every row in the same unit with the same d(scaled row)/d(unit)."""
        return cls((unit,) * rows, np.full(rows, float(per_unit)))


class ConstraintBlock(ABC):
    """One named group of inequality rows g >= 0 (scaled to O(1)).

    Subclasses set ``name`` and implement :meth:`row_names`, :meth:`values`, :meth:`jacobian` and
    :meth:`relaxation` (the rows' physical unit); they may override :meth:`clearance`, :meth:`limit_name`
    and, for rows of Xi only, :meth:`shared_key`. Row names start with ``name + "."``.
    """

    name: str

    @abstractmethod
    def row_names(self) -> list[str]:
        """One name per row, in row order."""

    @abstractmethod
    def values(self, state: SampleState) -> Array:
        """The solver's rows at ``state``, (m,), feasible where >= 0."""

    @abstractmethod
    def jacobian(self, state: SampleState, partials: SamplePartials) -> BlockJacobian:
        """Partials of :meth:`values` w.r.t. q9 and Xi."""

    @abstractmethod
    def relaxation(self, values: Array) -> Relaxation:
        """Each row's physical unit and d(row)/d(one unit of its limit relaxed) at the rows' ``values``."""

    def clearance(self) -> Array | float:
        """Added to :meth:`values` gives the nominal margins (a safety only the optimiser keeps); default 0."""
        return 0.0

    def limit_name(self, row: str) -> str:
        """The physical limit a row holds (rows at different samples of one limit give the same name)."""
        return _SAMPLE.sub("", row)

    def shared_key(self) -> Hashable | None:
        """For rows of Xi alone: a key equal for blocks with the same rows (held once in a mix); else None.

        A study of several tasks stacks every task's blocks; two blocks of Xi only with equal keys
        are the same rows (linearly dependent, a degenerate QP), so the stacked problem keeps the first.
        """
        return None


class PerSampleBlock(ConstraintBlock):
    """A block with the same rows at every sample time, named ``<name>.<row> at t=<t> s``."""

    times: Array
    sample_rows: tuple[str, ...]
    #: Pairs (a, b) of this block's per-sample rows whose values add up to a constant (the lower
    #: and upper limit of one quantity): g_a + g_b does not depend on z. A sparse solver may hold
    #: such a pair as one two-sided row 0 <= g_a <= g_a + g_b (half the rows, same feasible set).
    pairs: tuple[tuple[int, int], ...] = ()

    def row_names(self) -> list[str]:
        """Sample-major names: every row of sample 0, then of sample 1, ..."""
        return [f"{self.name}.{row} at t={t:.4g} s" for t in self.times for row in self.sample_rows]


class Objective(Protocol):
    """The NLP's objective: a value and its gradient w.r.t. per-sample q9 and Xi."""

    name: str
    unit: str

    def value(self, state: SampleState) -> float:
        """Objective at ``state`` [``unit``]."""
        ...

    def gradient(self, state: SampleState, partials: SamplePartials) -> tuple[Array, Array]:
        """(d/dq9 per sample (K, 3 n), d/dXi (n_xi,) [per m]) [``unit`` per unit of q9 or m]."""
        ...


class BlockLayout:
    """Rows of an ordered list of constraint blocks: names, slices, clearances, values and Jacobian."""

    def __init__(self, blocks: Sequence[ConstraintBlock]) -> None:
        names = [block.name for block in blocks]
        if len(set(names)) != len(names):
            raise ValueError(f"constraint block names must be unique: {names}")
        self.blocks = tuple(blocks)
        self.names: list[str] = []
        self.slices: dict[str, slice] = {}
        for block in self.blocks:
            rows = block.row_names()
            self.slices[block.name] = slice(len(self.names), len(self.names) + len(rows))
            self.names += rows
        #: added to the solver's rows gives the nominal margins
        self.clearance = np.zeros(len(self.names))
        for block in self.blocks:
            self.clearance[self.slices[block.name]] = block.clearance()

    def __len__(self) -> int:
        return len(self.names)

    def values(self, state: SampleState) -> Array:
        """Every block's rows, concatenated in block order."""
        out = np.concatenate([block.values(state) for block in self.blocks])
        if len(out) != len(self.names):
            raise AssertionError(f"{len(out)} constraint values for {len(self.names)} named rows")
        return out

    def jacobian(
        self,
        state: SampleState,
        partials: SamplePartials,
        to_z: Callable[[ConstraintBlock, BlockJacobian, Array], None],
        n: int,
        out: Array | None = None,
    ) -> Array:
        """Jacobian (m, n): each block's partials written into its rows by ``to_z(block, jacobian, rows)``.

        ``to_z`` belongs to the problem, which alone knows the layout of z (for several tasks it
        picks the block's task's spline matrices and columns); ``rows`` is the block's (rows, n) view
        of the Jacobian, zeros on entry into a new one. ``out``: a (m, n) array to write into instead
        (zeros on its first use; a block writes the same entries at every point, so what no block
        writes stays zero): no 20 MB allocation per point where the solver gathers the values at once.
        """
        out = np.zeros((len(self.names), n)) if out is None else out
        for block in self.blocks:
            to_z(block, block.jacobian(state, partials), out[self.slices[block.name]])
        return out

    def split(self, rows: Array) -> dict[str, Array]:
        """A row vector (margins, multipliers) cut into blocks by name."""
        rows = np.asarray(rows)
        return {name: rows[s] for name, s in self.slices.items()}

    def named(self, rows: Array) -> dict[str, dict[str, float]]:
        """A row vector as {block name: {row name: value}} (e.g. multipliers for a sensitivity report)."""
        rows = np.asarray(rows, dtype=float)
        return {name: dict(zip(self.names[s], map(float, rows[s]), strict=True)) for name, s in self.slices.items()}


class ScaledProblem(ABC):
    """The scaled NLP read from one evaluation: cost, inequality rows, equalities and nominal margins.

    A task's problem (:class:`hiab_sim.study.nlp.task_problem.TaskProblem`) and a study's (its tasks'
    stacked, :class:`hiab_sim.study.nlp.problem.StudyProblem`) read them alike from their
    :meth:`evaluate`; each sets ``cost_scale`` [the objective's unit] and ``clearance`` (per row, scaled).
    """

    cost_scale: float
    clearance: Array

    @abstractmethod
    def evaluate(self, z: Array) -> Any:
        """Everything computed at the point z: ``cost`` [the objective's unit], ``constraints``, ``equalities``.

        Typed by each problem (:class:`~hiab_sim.study.nlp.task_problem.Evaluation`,
        :class:`~hiab_sim.study.nlp.problem.StudyEvaluation`, both frozen).
        """

    def cost(self, z: Array) -> float:
        """Scaled cost f / f_scale (a study: the weighted sum sum_k w_k f_k over its tasks)."""
        return self.evaluate(z).cost / self.cost_scale

    def constraints(self, z: Array) -> Array:
        """Scaled inequality rows g(z) >= 0 (a study: every task's rows, stacked)."""
        return self.evaluate(z).constraints

    def equalities(self, z: Array) -> Array:
        """Rest-to-rest equalities, linear in the spline coefficients (a study: every task's)."""
        return self.evaluate(z).equalities

    def margins(self, z: Array) -> Array:
        """Nominal scaled inequality margins (feasible where >= 0): the solver's rows without the clearance.

        The tracking bands and envelope margins stay as the problem holds them (``tightened``);
        only the working-range clearance, a safety the optimiser adds for its own optimum, is removed.
        """
        return self.evaluate(z).constraints + self.clearance


def bound_row_name(variable: str, side: str, value_m: float) -> str:
    """The name of a design variable's bound as a row (``bound tilt.L up = 1.3 m``): sensitivities, least margin."""
    return f"bound {variable} {side} = {value_m:g} m"

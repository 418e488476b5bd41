"""Energy map: the study's objective, net energy and binding constraint over a 2-D grid of two link lengths.

Two of the six link lengths Xi (``lift.L``, ``lift.Lc0``, ``lift.Lc``, ``tilt.L``, ...) span a
grid over their study bounds (const_g); the other four stay at the base design, which is the
optimum of a result folder or the study's start. The joint trajectory is fixed at the base
design's (the optimum's spline, or the start's inverse-kinematics fit), so every cell answers:
"what would this mounting cost on that motion?".

Per design, on the analytic path with all designs stacked into the sample axis
(:mod:`hiab_sim.dynamics.analytic_batch`):

* the cost of eq. ``costf2``, f = 1/2 Dt sum_k (sum_i P_i(t_k))^2 [W^2 s] on the collocation
  grid (``cost``), and the study's objective (any registered one,
  :data:`hiab_sim.study.nlp.objectives.OBJECTIVES`: the optimiser's own value on the collocation
  grid, e.g. the smoothed battery energy) divided by its value at the study's start (``objective``);
* the net electrical energy and the energy drawn without regeneration [J], trapezoid on the fine
  grid (as in ``result.json``); ``battery_energy`` is the energy the battery delivers
  (:func:`hiab_sim.emla.battery.battery_power`, exact kinks, fine grid); with the study's duty model
  (:func:`hiab_sim.study.nlp.task_problem.duty_options`) every power is the hot windings' and the rest's
  hold is in the battery energy, as in ``result.json`` (one design at a time, not batched);
* the scaled margins of every constraint row that depends on Xi, as the optimiser holds them on
  the collocation grid: EMLA envelope (const_e, const_f, >= envelope_margin), strokes (const_j)
  at every sample and at both ends of the working range. Rows that depend on the trajectory only
  (tracking const_b..const_d, joint range const_h/const_k, joint velocity const_i) do not change
  over the map; they hold at the base design. A cell is feasible when every margin is >= -
  :data:`FEASIBILITY_TOLERANCE`; the binding constraint is the row with the smallest margin (min
  over time).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiab_sim.crane.description import CHAIN_NAMES, LinkLengths
from hiab_sim.crane.names import ACTUATOR_NAMES as ACTUATORS
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.dynamics.samples import ActuatorSamples
from hiab_sim.emla import ENVELOPE_LIMIT_NAMES, electrical_power, energy_summary, envelope_margins
from hiab_sim.emla.battery import battery_power, rest_battery_energy, trapezoid_weights
from hiab_sim.emla.duty_energy import DriveDuty, DutyOptions, drive_duty
from hiab_sim.errors import InvalidInputError
from hiab_sim.results.read import open_run, read_result
from hiab_sim.results.schema import Result
from hiab_sim.study.analysis.buildable import RobustXi, replace_lengths
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.nlp.interface import SampleState
from hiab_sim.study.nlp.task_problem import STROKE_SCALE, TaskProblem

Array = NDArray[np.float64]

#: The six link lengths in the order of Xi.
VARIABLES = tuple(f"{chain}.{key}" for chain in CHAIN_NAMES for key in ("L", "Lc0", "Lc"))
#: Scaled margin below which a cell counts as infeasible (SLSQP's optimum violates rows by ~1e-10).
FEASIBILITY_TOLERANCE = 1e-8
#: Designs per vectorised pass (bounds the memory of the stacked samples).
CHUNK = 256


@dataclass(frozen=True)
class BaseDesign:
    """The design the map varies around: Xi [m] and the fixed joint trajectory on the fine grid."""

    xi: Array  # (6,)
    time: Array  # (K,) fine grid [s]
    position: Array  # (K, 3)
    velocity: Array
    acceleration: Array
    source: str  # "optimum of <folder>" or "start of the study"


def start_design(problem: TaskProblem) -> BaseDesign:
    """The study's start: its initial lengths and the inverse-kinematics spline fit."""
    times = problem.study.grid.fine_times()
    joints = tr.evaluate(problem.basis, problem.c_ref, times)
    return BaseDesign(
        problem.study.initial_lengths.as_array(),
        times,
        joints.position,
        joints.velocity,
        joints.acceleration,
        "start of the study (initial lengths, inverse-kinematics trajectory)",
    )


def optimum_design(folder: str | Path) -> BaseDesign:
    """The optimum of a result folder: ``result.json``'s optimal lengths and ``trajectory.npz``'s motion.

    Read through the one result-folder reader (:func:`hiab_sim.results.read.open_run`).
    """
    run = open_run(folder, Result)
    return BaseDesign(
        run.result.optimal.lengths.as_array(),
        run.trajectory.time(),
        run.trajectory.design("optimal", "position"),
        run.trajectory.design("optimal", "velocity"),
        run.trajectory.design("optimal", "acceleration"),
        f"optimum of {run.folder} (its lengths and trajectory)",
    )


def result_study(folder: str | Path) -> str:
    """The study file a result folder was optimised from (``result.json``'s ``study``)."""
    return read_result(folder).study


@dataclass(frozen=True)
class DesignValues:
    """Values of D designs on the fixed trajectory (see the module docstring)."""

    xi: Array  # (D, 6) [m]
    cost: Array  # (D,) [W^2 s], collocation grid
    objective: Array  # (D,) the study's objective (any registered one) / its value at the study's start
    net_energy: Array  # (D,) [J], fine grid
    drawn_energy: Array  # (D,) [J], fine grid, without regeneration
    margins: Array  # (D, R) scaled, min over time per row
    names: tuple[str, ...]  # R row names
    battery_energy: Array  # (D,) [J], fine grid, exact (hiab_sim.emla.battery: shared DC bus, efficiencies)

    @property
    def binding(self) -> NDArray[np.int64]:
        """Index into ``names`` of the smallest margin, (D,)."""
        return np.argmin(self.margins, axis=1)

    @property
    def feasible(self) -> NDArray[np.bool_]:
        """Every Xi-dependent row holds (>= -FEASIBILITY_TOLERANCE), (D,)."""
        return np.asarray(self.margins.min(axis=1) >= -FEASIBILITY_TOLERANCE)


def margin_names() -> tuple[str, ...]:
    """Names of the Xi-dependent constraint rows, in the column order of ``DesignValues.margins``."""
    names = [f"envelope.{a}.{lim}" for a in ACTUATORS for lim in ENVELOPE_LIMIT_NAMES]
    strokes = [f"{c}.{w}" for c in CHAIN_NAMES for w in ("x >= 0", "x <= Lc", "x <= stroke")]
    names += [f"stroke.{s}" for s in strokes]
    names += [f"working_range.{s} at the {end} end" for end in ("low", "up") for s in strokes]
    return tuple(names)


def _stroke_rows(xi: Array, x: Array, strokes: Array) -> Array:
    """const_j per chain, (D, ..., 6) scaled: x >= 0, Lc - x >= 0, stroke - x >= 0 (x: (D, ..., 2))."""
    cols = []
    for j in range(2):
        lc = xi[:, 3 * j + 2].reshape((-1,) + (1,) * (x.ndim - 2))
        cols += [x[..., j], lc - x[..., j], strokes[j] - x[..., j]]
    return np.stack(cols, axis=-1) / STROKE_SCALE


def _duty_powers(
    problem: TaskProblem, options: DutyOptions, time: Array, f: Array, v: Array, a: Array, exact: bool = False
) -> tuple[Array, Array, list[tuple[DriveDuty, ...]]]:
    """(drive powers (3, D, K) [W], rest energies summed over drives (D,) [J], each design's duties)."""
    D = f.shape[0]
    duties = [
        tuple(
            drive_duty(p, time, f[d, :, i], v[d, :, i], a[d, :, i], options, exact) for i, p in enumerate(problem.emlas)
        )
        for d in range(D)
    ]
    power = np.array([[dd[i].power for dd in duties] for i in range(len(problem.emlas.as_tuple()))])
    rest = np.array([sum(x.rest_energy for x in dd) for dd in duties])
    return power, rest, duties


def evaluate_designs(problem: TaskProblem, base: BaseDesign, xi: Array) -> DesignValues:
    """Objective, energies and Xi-dependent margins of designs xi (D, 6) on the base trajectory."""
    xi = np.atleast_2d(np.asarray(xi, dtype=float))
    ff = problem.study.grid.fine_factor
    if len(base.time) != len(problem.study.grid.fine_times()):
        raise InvalidInputError(
            "result trajectory", f"{len(base.time)} samples", "must be on this study's fine grid (same study)"
        )
    crane = problem.study.crane
    tcp = problem.tcp_force
    strokes = np.array([chain.stroke for chain in crane.chains])
    working = np.array([[w[0] for w in problem.working] + [0.0], [w[1] for w in problem.working] + [0.0]])
    weights = trapezoid_weights(base.time)
    joints = tr.JointTrajectory(
        base.time[::ff], base.position[::ff], base.velocity[::ff], base.acceleration[::ff]
    )  # the fixed trajectory on the collocation grid, what the optimiser's objective sees
    tcp_samples = problem.kin.samples(joints.position, joints.velocity, joints.acceleration)
    parts: list[tuple[Array, ...]] = []
    for lo in range(0, len(xi), CHUNK):
        block = xi[lo : lo + CHUNK]
        f, v, a, x = batched_inverse_dynamics(crane, block, base.position, base.velocity, base.acceleration, tcp)
        options = problem.duty_options
        if options is None:
            power = np.stack(
                [electrical_power(p, f[..., i], v[..., i], a[..., i]) for i, p in enumerate(problem.emlas)]
            )
            colloc_power, duties = power[..., ::ff], None
            exact_power = np.stack(  # exact brake switching and loss kinks, as the report's battery energy
                [electrical_power(p, f[..., i], v[..., i], a[..., i], exact=True) for i, p in enumerate(problem.emlas)]
            )
            rest_exact = np.zeros(len(block))
        else:  # hot windings and the rest's hold, as the problem evaluates them
            power, _, _ = _duty_powers(problem, options, base.time, f, v, a)
            colloc_power, _, duties = _duty_powers(problem, options, joints.time, f[:, ::ff], v[:, ::ff], a[:, ::ff])
            exact_power, rest_exact, _ = _duty_powers(problem, options, base.time, f, v, a, exact=True)
        total = power.sum(axis=0)  # (D, K)
        colloc = colloc_power.sum(axis=0)
        objective = np.array(
            [
                problem.objective.value(
                    collocation_state(
                        joints,
                        tcp_samples,
                        block[d],
                        f,
                        v,
                        a,
                        x,
                        colloc_power,
                        ff,
                        d,
                        None if duties is None else duties[d],
                    )
                )
                for d in range(len(block))
            ]
        )
        cost = 0.5 * problem.dt * np.sum(colloc**2, axis=1)
        net, drawn = energy_summary(base.time, total)
        battery = battery_power(np.moveaxis(exact_power, 0, -1), problem.emlas.battery)[1] @ weights  # (D,) [J]
        battery = battery + rest_battery_energy([0.0], problem.emlas.battery)[1] * rest_exact
        fc, vc, ac = f[:, ::ff], v[:, ::ff], a[:, ::ff]
        env = np.stack(
            [envelope_margins(p, fc[..., i], vc[..., i], ac[..., i]) for i, p in enumerate(problem.emlas)], axis=1
        )  # (3 limits, 3 actuators, D, Kc) -> rows actuator-major
        env = (env - problem.envelope_margin) / (1.0 - problem.envelope_margin)
        env_rows = np.transpose(env.min(axis=-1), (2, 1, 0)).reshape(len(block), 9)
        stroke_rows = _stroke_rows(block, x[:, ::ff, :2], strokes).min(axis=1)
        _, _, _, xw = batched_inverse_dynamics(crane, block, working, np.zeros((2, 3)), np.zeros((2, 3)))
        work_rows = _stroke_rows(block, xw[..., :2], strokes).reshape(len(block), 12)
        margins = np.concatenate([env_rows, stroke_rows, work_rows], axis=1)
        parts.append((cost, objective / problem.cost_scale, net, drawn, margins, battery))
    cost, objective, net, drawn, margins, battery = (np.concatenate([p[k] for p in parts]) for k in range(6))
    robust, robust_names = _robust_rows(problem, base, xi)
    margins = np.concatenate([margins, robust], axis=1)
    return DesignValues(xi, cost, objective, net, drawn, margins, (*margin_names(), *robust_names), battery)


def collocation_state(
    joints: tr.JointTrajectory,
    tcp: tr.TcpSamples,
    xi: Array,
    f: Array,
    v: Array,
    a: Array,
    x: Array,
    power: Array,
    ff: int,
    d: int,
    duty: tuple[DriveDuty, ...] | None = None,
) -> SampleState:
    """Design d of a batch as the NLP's objectives see it: its samples on the collocation grid (every ``ff``-th).

    ``power`` (3, D, Kc) is already on the collocation grid; ``duty`` the design's duty model, if any.
    """
    actuators = ActuatorSamples(f[d, ::ff], v[d, ::ff], a[d, ::ff], x[d, ::ff])
    return SampleState(LinkLengths.from_array(xi), joints, tcp, actuators, power[:, d, :].T, duty=duty)


def _robust_rows(problem: TaskProblem, base: BaseDesign, xi: Array) -> tuple[Array, list[str]]:
    """The optimiser's rows of Xi only held within the manufacturing tolerance, per design (D, R).

    They depend on the link lengths alone (no samples), so each design is one call of the block
    (:class:`hiab_sim.study.analysis.buildable.RobustXi`: the buildable range, the mounting space).
    """
    blocks = [b for b in problem.layout.blocks if isinstance(b, RobustXi)]
    if not blocks:
        return np.zeros((len(xi), 0)), []
    state = problem.evaluate(problem.initial_point(LinkLengths.from_array(base.xi)))
    # nominal margins as TaskProblem.margins gives them: the rows without the optimiser's clearance
    rows = np.array([np.concatenate([b.values(replace_lengths(state, x)) + b.clearance() for b in blocks]) for x in xi])
    return rows, [name for b in blocks for name in b.row_names()]


@dataclass(frozen=True)
class EnergyMap:
    """A 2-D map: axes of two link lengths [m] and the design values on their grid (n0 x n1, row = axis 0)."""

    variables: tuple[str, str]
    axes: tuple[Array, Array]
    values: DesignValues  # D = n0 n1 designs, axis 0 major
    base: BaseDesign
    at_base: DesignValues  # the base design itself (the optimum's or start's own value)
    start_xi: Array
    low: Array  # study bounds of Xi [m]
    up: Array
    objective: str  # the study's objective (a name of the objective registry)

    def grid(self, array: NDArray[Any]) -> NDArray[Any]:
        """Reshape a per-design array (D,) to the grid (n0, n1)."""
        return np.asarray(array).reshape(len(self.axes[0]), len(self.axes[1]))


def parse_variables(text: str) -> tuple[int, int]:
    """Indices into Xi of ``"lift.L,tilt.L"``; two distinct names of :data:`VARIABLES`."""
    names = [n.strip() for n in text.split(",")]
    if len(names) != 2 or names[0] == names[1] or any(n not in VARIABLES for n in names):
        raise InvalidInputError("--vars", text, f"must be two distinct names of {', '.join(VARIABLES)}")
    return VARIABLES.index(names[0]), VARIABLES.index(names[1])


def energy_map(problem: TaskProblem, base: BaseDesign, variables: tuple[int, int], n: int) -> EnergyMap:
    """Evaluate the n x n grid of two link lengths over their study bounds, the rest at the base design."""
    if n < 2:
        raise InvalidInputError("--grid", n, "must be >= 2")
    low, up = np.asarray(problem.study.bounds.xi_low), np.asarray(problem.study.bounds.xi_up)
    i, j = variables
    a0, a1 = np.linspace(low[i], up[i], n), np.linspace(low[j], up[j], n)
    xi = np.repeat(base.xi[None], n * n, axis=0)
    g0, g1 = np.meshgrid(a0, a1, indexing="ij")
    xi[:, i], xi[:, j] = g0.ravel(), g1.ravel()
    return EnergyMap(
        (VARIABLES[i], VARIABLES[j]),
        (a0, a1),
        evaluate_designs(problem, base, xi),
        base,
        evaluate_designs(problem, base, base.xi[None]),
        problem.study.initial_lengths.as_array(),
        low,
        up,
        problem.objective.name,
    )


def base_lengths(base: BaseDesign) -> LinkLengths:
    """The base design's Xi as :class:`LinkLengths`."""
    return LinkLengths.from_array(base.xi)

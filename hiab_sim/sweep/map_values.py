"""The values of designs on a fixed trajectory: the study's objective, costf2, energies and the rows of Xi.

A design Xi (the machine's decision variables, e.g. ``lift.L`` of the XS 031 or ``boom.L`` of the
eXact arm) is evaluated on every task of the study with each task's trajectory held at the base
design's spline coefficients c_k (:class:`hiab_sim.sweep.energy_map.BaseDesign`), so a value answers
"what would this mounting cost on that motion?". Every number comes from the study's own NLP
(:class:`hiab_sim.study.nlp.problem.StudyProblem`, one task or many, any machine):

* ``objective``: the study's objective, any registered one
  (:data:`hiab_sim.study.nlp.objectives.OBJECTIVES`), weighted over the tasks, sum_k w_k f_k
  [its unit] (``objective_value``), and divided by its value at the study's start
  (``objective``, the optimiser's scaled cost);
* ``costf2``: sum_k w_k 1/2 Dt sum_j (sum_i P_i(t_j))^2 [W^2 s] of eq. ``costf2`` on each task's
  collocation grid, whatever the objective;
* ``net_energy``, ``drawn_energy`` [J]: sum_k w_k of the trapezoid integrals of the summed drive
  power (regeneration credited, or not) on each task's fine grid, as ``result.json``; with the
  study's duty model (:func:`hiab_sim.study.nlp.task_problem.duty_options`) every power is the hot
  windings' (R_s(T));
* ``battery_energy`` [J]: sum_k w_k of the energy the battery delivers
  (:func:`hiab_sim.emla.battery_energy`, exact kinks and drive losses, fine grid) and, with a duty
  model, the rest's hold (:func:`hiab_sim.emla.battery.rest_battery_energy`), as ``result.json``;
* ``margins``: the optimiser's nominal scaled margins (rows plus clearance,
  :meth:`StudyProblem.margins`) of every constraint block whose rows depend on Xi (their partial in
  Xi is not zero at the base: envelope const_e/const_f, strokes const_j, working and buildable
  range, thermal, brake, structure rows), each limit reduced to its least margin over time
  (:meth:`~hiab_sim.study.nlp.interface.ConstraintBlock.limit_name`), named ``<task>: <limit>`` in a
  mix. Blocks of the trajectory only (tracking const_b..const_d, joint range const_h/const_k, joint
  velocity const_i) do not change over a map and are left out.

A weight w_k is the task's share (e.g. cycles per hour); one task of weight 1 is its own values.
A design the inverse dynamics refuses (outside the model's domain, e.g. a stroke that cannot
cover the joint range the ID checks) gets NaN values and the margin -2 ``FEASIBILITY_TOLERANCE``
in the row :data:`DOMAIN_ROW` (infeasible); its rows of Xi alone (working and buildable range,
mounting space: blocks with a :meth:`~hiab_sim.study.nlp.interface.ConstraintBlock.shared_key`)
are still evaluated, so where one of them is violated it is the binding row and says why.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla import battery_energy, electrical_power, energy_summary
from hiab_sim.emla.battery import rest_battery_energy
from hiab_sim.emla.duty_energy import drive_duty
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.analysis.buildable import replace_lengths
from hiab_sim.study.nlp.objectives import costf2
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.report.design_check import fine_problem

#: Scaled margin below which a cell counts as infeasible (SLSQP's optimum violates rows by ~1e-10).
FEASIBILITY_TOLERANCE = 1e-8
#: The row of a design the inverse dynamics refuses (margin -2 FEASIBILITY_TOLERANCE there, +inf for every other).
DOMAIN_ROW = "domain: the inverse dynamics refuses the design"
#: The margin of :data:`DOMAIN_ROW` for a refused design: infeasible, below any row that merely holds.
DOMAIN_MARGIN = -2.0 * FEASIBILITY_TOLERANCE


@dataclass(frozen=True)
class DesignValues:
    """Values of D designs on the fixed trajectories (module docstring); energies weighted over the tasks."""

    xi: Array  # (D, n_xi) decision variables [m]
    objective: Array  # (D,) sum_k w_k f_k / its value at the study's start [-]
    objective_value: Array  # (D,) sum_k w_k f_k [the objective's unit]
    costf2: Array  # (D,) sum_k w_k costf2_k [W^2 s], collocation grids
    net_energy: Array  # (D,) [J], fine grids
    drawn_energy: Array  # (D,) [J], fine grids, without regeneration
    battery_energy: Array  # (D,) [J], fine grids, exact (shared DC bus, efficiencies; the rest's hold with a duty)
    margins: Array  # (D, R) scaled, least over time per limit
    names: tuple[str, ...]  # R limit names

    @property
    def binding(self) -> NDArray[np.int64]:
        """Index into ``names`` of the smallest margin, (D,)."""
        return np.argmin(self.margins, axis=1)

    @property
    def feasible(self) -> NDArray[np.bool_]:
        """Every Xi-dependent row holds (>= -FEASIBILITY_TOLERANCE), (D,)."""
        return np.asarray(self.margins.min(axis=1) >= -FEASIBILITY_TOLERANCE)


@dataclass(frozen=True)
class TaskEnergy:
    """One task's energies of one design on its fine grid [J]."""

    net: float
    drawn: float
    battery: float


def task_energy(fine: TaskProblem, xi: Array, coefficients: Array) -> TaskEnergy:
    """Net, drawn and battery energy [J] of design ``xi`` on ``fine``'s grid for fixed spline coefficients.

    The task's joint samples B c on its fine grid, the inverse dynamics of its machine
    (``fine.model``, its ID path and TCP force), the drive powers as the NLP's state holds them
    (hot windings with a duty model) and the battery's energy exact, as ``result.json`` reports it
    (:func:`hiab_sim.study.report.energy_section.design_energy`). The constraint rows are not
    evaluated (the fine grid's thermal rows cost more than the rest together).
    """
    design = fine.model.design(xi)
    joints = fine.joints(np.asarray(coefficients, dtype=float))
    act = fine.model.inverse_dynamics(design, fine.id_path)(
        JointSamples(joints.position, joints.velocity, joints.acceleration), tcp_force=fine.tcp_force
    )
    t, emlas, options = fine.times, fine.emlas, fine.duty_options
    f, v, a = act.force, act.velocity, act.acceleration
    if options is None:
        power = np.column_stack([electrical_power(p, f[:, i], v[:, i], a[:, i]) for i, p in enumerate(emlas)])
        exact = np.column_stack(
            [electrical_power(p, f[:, i], v[:, i], a[:, i], exact=True) for i, p in enumerate(emlas)]
        )
        rest = 0.0
    else:  # hot windings and the rest's hold, exact switching for the battery's number
        power = np.column_stack(
            [drive_duty(p, t, f[:, i], v[:, i], a[:, i], options).power for i, p in enumerate(emlas)]
        )
        drives = [drive_duty(p, t, f[:, i], v[:, i], a[:, i], options, exact=True) for i, p in enumerate(emlas)]
        exact = np.column_stack([d.power for d in drives])
        rest = rest_battery_energy([d.rest_energy for d in drives], emlas.battery)[0]
    net, drawn = energy_summary(t, power.sum(axis=1))
    return TaskEnergy(float(net), float(drawn), battery_energy(t, exact, emlas.battery).energy + rest)


class DesignEvaluator:
    """Evaluates designs of a study on fixed trajectories (module docstring).

    Args:
        problem: The study's NLP (one task or many; any machine).
        xi: The base design [m] (the Xi-dependence of the rows is read at it).
        coefficients: Each task's fixed spline coefficients (n, N_k).

    """

    def __init__(self, problem: StudyProblem, xi: Array, coefficients: tuple[Array, ...]) -> None:
        if len(coefficients) != problem.n_tasks:
            raise InvalidInputError("base trajectory", f"{len(coefficients)} tasks", f"the study has {problem.n_tasks}")
        self.problem = problem
        self.coefficients = coefficients
        self.fine = tuple(fine_problem(p) for p in problem.problems)
        z = self.point(xi)
        depends = np.any(problem.constraints_jacobian(z)[:, : problem.n_xi] != 0.0, axis=1)
        self.base_states = problem.evaluate(z).tasks
        self.xi_only = tuple(held for held in problem.blocks if held.block.shared_key() is not None)
        names: list[str] = []
        groups: dict[str, list[int]] = {}
        for held in problem.blocks:
            if not depends[held.rows].any():
                continue  # a block of the trajectory only
            local = problem.problems[held.task].constraint_names[held.local]
            for r, row in zip(range(held.rows.start, held.rows.stop), local, strict=True):
                name = problem.row_name(held.task, held.block.limit_name(row))
                if name not in groups:
                    names.append(name)
                    groups[name] = []
                groups[name].append(r)
        self.names = (*names, DOMAIN_ROW)
        self.groups = [np.array(groups[n], dtype=np.intp) for n in names]

    def point(self, xi: Array) -> Array:
        """The study's z of design ``xi`` with every task's fixed coefficients."""
        p = self.problem
        return p.initial_point(p.problems[0].model.design(xi), list(self.coefficients))

    def evaluate(self, xi: Array) -> DesignValues:
        """Values of designs ``xi`` (D, n_xi) [m]."""
        xi = np.atleast_2d(np.asarray(xi, dtype=float))
        p, D = self.problem, len(xi)
        weights = p.weights
        out = {k: np.full(D, np.nan) for k in ("objective", "value", "costf2", "net", "drawn", "battery")}
        margins = np.full((D, len(self.names)), np.inf)
        for d in range(D):
            try:
                z = self.point(xi[d])
                ev = p.evaluate(z)
                energies = [task_energy(fine, xi[d], c) for fine, c in zip(self.fine, self.coefficients, strict=True)]
            except InvalidInputError:  # the inverse dynamics refuses the design: recorded in its margins
                margins[d] = self._refused_margins(xi[d])
                continue
            rows = ev.constraints + p.clearance
            margins[d, :-1] = [rows[g].min() for g in self.groups]
            out["value"][d] = ev.cost
            out["objective"][d] = ev.cost / p.cost_scale
            out["costf2"][d] = sum(
                w * costf2(tp.emlas, tp.dt).value(t) for w, tp, t in zip(weights, p.problems, ev.tasks, strict=True)
            )
            out["net"][d] = float(weights @ [e.net for e in energies])
            out["drawn"][d] = float(weights @ [e.drawn for e in energies])
            out["battery"][d] = float(weights @ [e.battery for e in energies])
        return DesignValues(
            xi,  # (D, n_xi)
            out["objective"],
            out["value"],
            out["costf2"],
            out["net"],
            out["drawn"],
            out["battery"],
            margins,
            self.names,
        )

    def _refused_margins(self, xi: Array) -> Array:
        """Margins of a design the inverse dynamics refuses: its rows of Xi alone, the domain row, +inf elsewhere."""
        p = self.problem
        rows = np.full(len(p.constraint_names), np.inf)
        for held in self.xi_only:
            state = replace_lengths(self.base_states[held.task], xi)
            try:
                rows[held.rows] = held.block.values(state) + held.block.clearance()
            except InvalidInputError:  # this block cannot evaluate the design either: the domain row binds
                continue
        return np.array([*(rows[g].min() for g in self.groups), DOMAIN_MARGIN])

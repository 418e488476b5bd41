"""Energy map: the study's objective, energies and binding constraint over a 2-D grid of two decision variables.

Two of the machine's decision variables Xi (named by the machine: ``lift.L``, ``lift.Lc0``, ... of
the XS 031, ``boom.L``, ``bucket.Gx``, ... of a machine file) span a grid over their study bounds
(const_g); the others stay at the base design, which is the optimum of a result folder or the
study's start. Every task's joint trajectory is fixed at the base design's (the optimum's spline,
or the start's inverse-kinematics fit), so every cell answers: "what would this mounting cost on
that motion?". A study of several tasks (a duty mix) is mapped as its NLP weighs it: the objective
sum_k w_k f_k, energies weighted by the tasks' weights, and every task's rows.

The values of a cell are those of :mod:`hiab_sim.sweep.map_values`: the study's objective (any
registered one) in its unit and divided by its value at the study's start, costf2 [W^2 s], the net,
drawn and battery energies [J] on the fine grids, and the scaled margins of every row that depends
on Xi as the optimiser holds them. A cell is feasible when every margin is >= -
:data:`~hiab_sim.sweep.map_values.FEASIBILITY_TOLERANCE`; the binding constraint is the limit with
the smallest margin (least over time).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.results.read import open_run, read_result
from hiab_sim.results.schema import Result
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.sweep.map_values import FEASIBILITY_TOLERANCE, DesignEvaluator, DesignValues

__all__ = [
    "FEASIBILITY_TOLERANCE",
    "BaseDesign",
    "DesignValues",
    "EnergyMap",
    "energy_map",
    "evaluate_designs",
    "optimum_design",
    "parse_variables",
    "result_study",
    "start_design",
]


@dataclass(frozen=True)
class BaseDesign:
    """The design a map varies around: Xi [m] and each task's fixed B-spline coefficients (n, N_k)."""

    xi: Array  # (n_xi,)
    coefficients: tuple[Array, ...]  # one per task, in the study's task order
    source: str  # "optimum of <folder>" or "start of the study"


def start_design(problem: StudyProblem) -> BaseDesign:
    """The study's start: its initial design and every task's inverse-kinematics spline fit."""
    return BaseDesign(
        problem.study.initial_lengths.as_array(),
        tuple(p.c_ref for p in problem.problems),
        "start of the study (initial lengths, inverse-kinematics trajectory)",
    )


def optimum_design(folder: str | Path, problem: StudyProblem) -> BaseDesign:
    """The optimum of a result folder: ``result.json``'s optimal design and ``trajectory.npz``'s motion per task.

    Read through the one result-folder reader (:func:`hiab_sim.results.read.open_run`). Each task's
    coefficients are the least-squares fit B c = q of its optimal joint positions on its fine grid,
    exact to round-off for a trajectory that is the study's spline (B has full column rank).
    """
    run = open_run(folder, Result)
    xi = run.result.optimal.lengths.as_array()
    if len(xi) != problem.n_xi:
        raise InvalidInputError(
            "--result", str(folder), f"holds {len(xi)} decision variables, the study {problem.n_xi}"
        )
    coefficients = []
    for k, p in enumerate(problem.problems):
        prefix = "" if problem.n_tasks == 1 else f"task{k}_"
        time, fine = run.trajectory.time(prefix), p.fine_times()
        if len(time) != len(fine) or not np.allclose(time, fine, rtol=0.0, atol=1e-9):
            raise InvalidInputError(
                f"--result ({prefix}time)", f"{len(time)} samples", "must be on this study's fine grid (same study)"
            )
        position = run.trajectory.design("optimal", "position", prefix)
        c = np.linalg.lstsq(p.basis.matrix(time), position, rcond=None)[0]  # (N, n)
        coefficients.append(np.ascontiguousarray(c.T))
    return BaseDesign(xi, tuple(coefficients), f"optimum of {run.folder} (its lengths and trajectory)")


def result_study(folder: str | Path) -> str:
    """The study file a result folder was optimised from (``result.json``'s ``study``)."""
    return read_result(folder).study


def evaluate_designs(problem: StudyProblem, base: BaseDesign, xi: Array) -> DesignValues:
    """Objective, costf2, energies and Xi-dependent margins of designs xi (D, n_xi) on the base trajectories."""
    return DesignEvaluator(problem, base.xi, base.coefficients).evaluate(xi)


@dataclass(frozen=True)
class EnergyMap:
    """A 2-D map: axes of two decision variables [m] and the design values on their grid (n0 x n1, row = axis 0)."""

    variables: tuple[str, str]
    axes: tuple[Array, Array]
    values: DesignValues  # D = n0 n1 designs, axis 0 major
    base: BaseDesign
    at_base: DesignValues  # the base design itself (the optimum's or start's own value)
    start_xi: Array
    low: Array  # study bounds of Xi [m]
    up: Array
    objective: str  # the study's objective (a name of the objective registry)
    objective_unit: str  # its unit (J for battery_energy, W^2 s for costf2)
    design_names: tuple[str, ...]  # the machine's decision variables, in the order of Xi
    tasks: tuple[tuple[str, float], ...]  # (name, weight) of every task

    def grid(self, array: NDArray[Any]) -> NDArray[Any]:
        """Reshape a per-design array (D,) to the grid (n0, n1)."""
        return np.asarray(array).reshape(len(self.axes[0]), len(self.axes[1]))

    def index(self, name: str) -> int:
        """Position of a decision variable in Xi."""
        return self.design_names.index(name)


def parse_variables(text: str | None, names: tuple[str, ...]) -> tuple[int, int]:
    """Indices into Xi of ``"lift.L,tilt.L"``: two distinct names of the machine's decision variables.

    None gives the first two (the XS 031's ``lift.L,lift.Lc0``: with ``working_range: crane`` a
    chain's L and Lc0 together keep its stroke on the joint range, so their map has a feasible region).
    """
    if text is None:
        return 0, 1
    given = [n.strip() for n in text.split(",")]
    if len(given) != 2 or given[0] == given[1] or any(n not in names for n in given):
        raise InvalidInputError("--vars", text, f"must be two distinct names of {', '.join(names)}")
    return names.index(given[0]), names.index(given[1])


def energy_map(problem: StudyProblem, base: BaseDesign, variables: tuple[int, int], n: int) -> EnergyMap:
    """Evaluate the n x n grid of two decision variables over their study bounds, the rest at the base design."""
    if n < 2:
        raise InvalidInputError("--grid", n, "must be >= 2")
    low, up = np.asarray(problem.study.bounds.xi_low), np.asarray(problem.study.bounds.xi_up)
    i, j = variables
    a0, a1 = np.linspace(low[i], up[i], n), np.linspace(low[j], up[j], n)
    xi = np.repeat(base.xi[None], n * n, axis=0)
    g0, g1 = np.meshgrid(a0, a1, indexing="ij")
    xi[:, i], xi[:, j] = g0.ravel(), g1.ravel()
    evaluator = DesignEvaluator(problem, base.xi, base.coefficients)
    names = tuple(problem.model.design_names)
    return EnergyMap(
        (names[i], names[j]),
        (a0, a1),
        evaluator.evaluate(xi),
        base,
        evaluator.evaluate(base.xi[None]),
        problem.study.initial_lengths.as_array(),
        low,
        up,
        problem.objective.name,
        problem.objective.unit,
        names,
        tuple((t.name, float(t.weight)) for t in problem.tasks),
    )

"""The Python API: load a study, optimise it, evaluate a design, read a result folder.

Four functions cover what the CLI does for a study, with typed values instead of files::

    import hiab_sim as hs

    study = hs.load_study("xs031_spiral")  # a shipped name or a path
    result = hs.optimize(study, out="runs/x")  # typed result, the files the CLI writes
    e = hs.evaluate(study, lengths, trajectory="fixed")  # or "reoptimize"
    r = hs.read_result("runs/x")

*Evaluating a design* means one of two things, named by ``trajectory``:

* ``"fixed"``: the study's own start trajectory for that design, the inverse-kinematics fit of the
  reference at the design's lengths (what ``optimize`` starts from): how the design does on the
  motion as planned, without re-planning;
* ``"reoptimize"``: the trajectory re-optimised for the design with its lengths held fixed (IPOPT
  on the task's NLP over the spline coefficients, the cross-evaluation's rule): how a machine built
  with those lengths does when driven as well as it can.

Either way every task of the study is evaluated on its fine grid with nominal bands (the
re-check's grid), so the numbers are those ``result.json`` reports for its designs. Whether a
design is buildable within the manufacturing tolerance is ``result.buildable`` of an optimisation,
not an evaluation of a single design.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

import numpy as np

from hiab_sim.crane.description import ChainLengths, LinkLengths
from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.errors import InvalidInputError
from hiab_sim.results.energy_sections import DesignEnergy
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import DesignSummary, Result
from hiab_sim.study.nlp.interface import N_XI
from hiab_sim.study.spec.study_file import Study, load_study

__all__ = ["DesignEvaluation", "TaskEvaluation", "evaluate", "load_study", "optimize", "read_result"]

#: The two meanings of evaluating a design (module docstring).
TRAJECTORIES = ("fixed", "reoptimize")
#: Largest scaled constraint violation at which a design serves a task (the solvers' tolerance).
FEASIBLE = 1e-6

#: What :func:`evaluate` accepts as a design: typed lengths, the six values of Xi in the result's
#: order [m], or a mapping chain name -> (L, Lc0, Lc) [m].
Lengths = LinkLengths | Sequence[float] | np.ndarray | Mapping[str, Sequence[float]]


@dataclass(frozen=True)
class TaskEvaluation:
    """One task of a study evaluated for one design on the task's fine grid.

    Attributes:
        task: The task's name.
        weight: Its weight in the study's mix.
        summary: Energies [J] (net and drawn electrical on the shared bus), per-actuator peaks and
            envelope margins, the largest scaled violation and the worst constraint, tracking errors;
            ``result.json``'s design summary.
        energy: Battery energy [J] at the battery terminals, the seed's cost ``costf2`` [W^2 s],
            per-actuator energies and the thermal state at the study's duty.
        feasible: True where the largest scaled violation is at most :data:`FEASIBLE`.
        solver_message: With ``trajectory="reoptimize"``, what IPOPT said; else None.

    """

    task: str
    weight: float
    summary: DesignSummary
    energy: DesignEnergy
    feasible: bool
    solver_message: str | None


@dataclass(frozen=True)
class DesignEvaluation:
    """A design evaluated on every task of a study (see :func:`evaluate`).

    Attributes:
        lengths: The design Xi [m].
        trajectory: ``"fixed"`` or ``"reoptimize"``.
        tasks: One :class:`TaskEvaluation` per task, in the study's order.
        battery_energy_J: The weighted sum over the tasks of the battery energy [J].
        net_electrical_energy_J: The weighted sum of the net electrical energy on the DC bus [J].
        max_violation: The largest scaled violation over the tasks.
        feasible: True where every task is served (:data:`FEASIBLE`).

    """

    lengths: LinkLengths
    trajectory: str
    tasks: tuple[TaskEvaluation, ...]
    battery_energy_J: float
    net_electrical_energy_J: float
    max_violation: float
    feasible: bool


def _as_study(study: Study | str | Path) -> Study:
    return study if isinstance(study, Study) else load_study(study)


def as_lengths(lengths: Lengths) -> LinkLengths:
    """A design as :class:`LinkLengths` from any form :func:`evaluate` accepts."""
    if isinstance(lengths, LinkLengths):
        return lengths
    if isinstance(lengths, Mapping):
        unknown = sorted(set(lengths) - set(ACTUATOR_NAMES[:2]))
        if unknown:
            raise InvalidInputError("lengths", unknown, f"chain names are {list(ACTUATOR_NAMES[:2])}")
        chains = {}
        for name in ACTUATOR_NAMES[:2]:
            if name not in lengths:
                raise InvalidInputError("lengths", sorted(lengths), f"needs every chain: {list(ACTUATOR_NAMES[:2])}")
            values = np.asarray(lengths[name], dtype=float)
            if values.shape != (3,):
                raise InvalidInputError(f"lengths.{name}", list(values.ravel()), "must be [L, Lc0, Lc]", "m")
            chains[name] = ChainLengths(*map(float, values))
        return LinkLengths(**chains)
    values = np.asarray(lengths, dtype=float)
    if values.shape != (N_XI,):
        raise InvalidInputError("lengths", list(values.ravel()), f"must be {N_XI} values [L, Lc0, Lc] per chain", "m")
    return LinkLengths.from_array(values)


def optimize(
    study: Study | str | Path,
    out: str | Path,
    *,
    starts: int = 1,
    resume: bool = False,
    force: bool = False,
    figures: bool = True,
    progress: TextIO | None = sys.stderr,
) -> Result:
    """Optimise a study and write its result folder; return the typed result.

    Writes what ``hiab-sim optimize --no-video`` writes (``result.json``, ``trajectory.npz``, the
    figures): the same function runs both. Bad input raises before anything is written.

    Args:
        study: A loaded study, a shipped study name or a study file.
        out: The result folder.
        starts: Feasible starts (1: the study's own start).
        resume: Continue from the folder's checkpoint.
        force: Take over a folder written by another study.
        figures: Write the figures.
        progress: Where iteration lines go (None: nowhere).

    """
    from hiab_sim.study.run import run_study

    output = run_study(
        _as_study(study), out, starts=starts, resume=resume, progress=progress, figures=figures, force=force
    )
    return output.result


def evaluate(study: Study | str | Path, lengths: Lengths, trajectory: str = "fixed") -> DesignEvaluation:
    """Evaluate a design on every task of a study: energies, margins, violations (module docstring).

    Args:
        study: A loaded study, a shipped study name or a study file.
        lengths: The design Xi [m] (:data:`Lengths`).
        trajectory: ``"fixed"`` (the inverse-kinematics start at these lengths) or ``"reoptimize"``
            (the trajectory re-optimised with the lengths fixed; needs CasADi).

    Raises:
        InvalidInputError: An unknown ``trajectory``, lengths of the wrong shape, or a design outside
            the model's domain (a chain that cannot close), naming the field.
        BackendUnavailableError: ``"reoptimize"`` without CasADi.

    """
    if trajectory not in TRAJECTORIES:
        raise InvalidInputError("trajectory", trajectory, f"one of {list(TRAJECTORIES)}")
    from hiab_sim.study.analysis.cross_evaluation import fixed_lengths_optimum, task_alone
    from hiab_sim.study.report.design_check import design_summary, fine_problem
    from hiab_sim.study.report.energy_section import design_energy

    loaded = _as_study(study)
    design = as_lengths(lengths)
    tasks = []
    for k, task in enumerate(loaded.tasks):
        alone = task_alone(loaded, k)  # the task's NLP as a study of its own
        problem = alone.problems[0]
        message = None
        if trajectory == "fixed":
            z = problem.initial_point(design)
        else:
            z, _, message = fixed_lengths_optimum(alone, design)
        fine = fine_problem(problem)
        check = design_summary(fine, z)
        tasks.append(
            TaskEvaluation(
                task=task.name,
                weight=float(task.weight),
                summary=check.summary,
                energy=design_energy(fine, check.evaluation),
                feasible=check.summary.max_violation <= FEASIBLE,
                solver_message=message,
            )
        )
    weights = np.array([t.weight for t in tasks])
    return DesignEvaluation(
        lengths=design,
        trajectory=trajectory,
        tasks=tuple(tasks),
        battery_energy_J=float(weights @ [t.energy.battery_energy_J for t in tasks]),
        net_electrical_energy_J=float(weights @ [t.summary.net_electrical_energy_J for t in tasks]),
        max_violation=max(t.summary.max_violation for t in tasks),
        feasible=all(t.feasible for t in tasks),
    )

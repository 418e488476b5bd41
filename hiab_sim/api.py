"""The Python API: load a study, optimise it, evaluate a design, read a result folder.

Four functions cover what the CLI does for a study, with typed values instead of files::

    import hiab_sim as hs

    study = hs.load_study("xs031_spiral")  # a shipped name or a path
    result = hs.optimize(study, out="runs/x")  # typed result, the files the CLI writes
    e = hs.evaluate(study, lengths, trajectory="fixed")  # or "reoptimize", or "optimum" with result="runs/x"
    r = hs.read_result("runs/x")

*Evaluating a design* means one of three things, named by ``trajectory``:

* ``"fixed"``: the study's own start trajectory for that design, the inverse-kinematics fit of the
  reference at the design's lengths (what ``optimize`` starts from): how the design does on the
  motion as planned, without re-planning;
* ``"reoptimize"``: the trajectory re-optimised for the design with its lengths held fixed (IPOPT
  on the task's NLP over the spline coefficients, the cross-evaluation's rule): how a machine built
  with those lengths does when driven as well as it can;
* ``"optimum"``: the trajectory of an optimisation's result folder (``result=``: each task's spline
  coefficients of the reported optimum, from the folder's ``checkpoint_0.json``) at the design's
  lengths: how another design (a rounded one, a pivot moved) does on the motion planned for the
  optimum. At the optimum's own lengths it gives ``result.json``'s optimal design.

Each way every task of the study is evaluated on its fine grid with nominal bands (the
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

from hiab_sim.crane.description import LinkLengths
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.design import MachineDesign
from hiab_sim.results.energy_sections import DesignEnergy
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import DesignSummary, Result
from hiab_sim.study.machines.protocol import Design, StudyMachine
from hiab_sim.study.spec.study_file import Study, load_study

__all__ = ["DesignEvaluation", "TaskEvaluation", "evaluate", "load_study", "optimize", "read_result"]

#: The three meanings of evaluating a design (module docstring).
TRAJECTORIES = ("fixed", "reoptimize", "optimum")
#: Largest scaled constraint violation at which a design serves a task (the solvers' tolerance).
FEASIBLE = 1e-6

#: What :func:`evaluate` accepts as a design of a study's machine: a typed design (a result's
#: ``lengths``: a crane file's LinkLengths, a machine file's MachineDesign), the values of Xi in the
#: order of the study's ``model.design_names`` [m], or a mapping from a chain's name to its values in
#: that order (a crane chain: (L, Lc0, Lc)) or from ``chain.variable`` to one value [m].
Lengths = Design | Sequence[float] | np.ndarray | Mapping[str, Sequence[float] | float]


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
        lengths: The design Xi [m] (the study's machine's design type).
        trajectory: ``"fixed"``, ``"reoptimize"`` or ``"optimum"``.
        tasks: One :class:`TaskEvaluation` per task, in the study's order.
        battery_energy_J: The weighted sum over the tasks of the battery energy [J].
        net_electrical_energy_J: The weighted sum of the net electrical energy on the DC bus [J].
        max_violation: The largest scaled violation over the tasks.
        feasible: True where every task is served (:data:`FEASIBLE`).

    """

    lengths: Design
    trajectory: str
    tasks: tuple[TaskEvaluation, ...]
    battery_energy_J: float
    net_electrical_energy_J: float
    max_violation: float
    feasible: bool


def _as_study(study: Study | str | Path) -> Study:
    return study if isinstance(study, Study) else load_study(study)


def as_design(model: StudyMachine, lengths: Lengths) -> Design:
    """A design of ``model`` from any form :func:`evaluate` accepts (:data:`Lengths`), checked by name and count.

    Raises:
        InvalidInputError: names that are not the model's decision variables, a missing one, or the
            wrong number of values, naming the field and the model's names.

    """
    names = model.design_names
    if isinstance(lengths, (LinkLengths, MachineDesign)):
        if tuple(lengths.names) != names:
            raise InvalidInputError("lengths", list(lengths.names), f"the study's decision variables are {list(names)}")
        return model.design(lengths.as_array())
    if isinstance(lengths, Mapping):
        return model.design(_mapped_values(names, lengths))
    order = f"must be {len(names)} values, in order {list(names)}"
    return model.design(_numbers("lengths", lengths, len(names), order))


def _mapped_values(names: tuple[str, ...], lengths: Mapping[str, object]) -> list[float]:
    """Values in ``names``' order from ``{"chain.var": value}`` or ``{"chain": [values in the chain's order]}``."""
    chains: dict[str, list[str]] = {}
    for name in names:
        chain, _, variable = name.partition(".")
        chains.setdefault(chain, []).append(variable)
    unknown = sorted(set(lengths) - set(names) - set(chains))
    if unknown:
        allowed = f"keys are the chains {list(chains)} or the variables {list(names)}"
        raise InvalidInputError("lengths", unknown, allowed)
    values: dict[str, float] = {}
    for chain, variables in chains.items():
        if chain in lengths:
            twice = [f"{chain}.{v}" for v in variables if f"{chain}.{v}" in lengths]
            if twice:
                raise InvalidInputError(f"lengths.{chain}", twice, "give a chain's values or its variables, not both")
            given = _numbers(f"lengths.{chain}", lengths[chain], len(variables), f"must be {variables}")
            values.update({f"{chain}.{v}": x for v, x in zip(variables, given, strict=True)})
    for name in names:
        if name in lengths:
            values[name] = _numbers(f"lengths.{name}", lengths[name], None, "must be one finite number")[0]
    missing = [name for name in names if name not in values]
    if missing:
        raise InvalidInputError("lengths", sorted(lengths), f"misses {missing} (needs every one of {list(names)})")
    return [values[name] for name in names]


def _numbers(field: str, given: object, count: int | None, allowed: str) -> list[float]:
    """``given`` as ``count`` finite numbers [m] (None: one scalar), else one line naming ``field``."""
    try:
        values = np.asarray(given, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(field, given, allowed, "m") from None
    shape_ok = values.shape == (() if count is None else (count,))
    if not shape_ok or not np.all(np.isfinite(values)):
        raise InvalidInputError(field, given, allowed, "m")
    return [float(v) for v in values.ravel()]


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


def _optimum_coefficients(loaded: Study, result: str | Path | None) -> list[np.ndarray]:
    """Each task's spline coefficients of a result folder's reported optimum (start 0's finished checkpoint)."""
    from hiab_sim.study.nlp.problem import StudyProblem
    from hiab_sim.study.solvers.slsqp import load_checkpoint, study_digest

    if result is None or isinstance(result, bool) or not isinstance(result, (str, Path)):
        raise InvalidInputError("result", result, 'the result folder whose optimum trajectory="optimum" evaluates on')
    data = load_checkpoint(Path(result), 0)
    if data is None or data.get("done") is not True:
        raise InvalidInputError("result", str(result), "a folder of a finished optimisation (checkpoint_0.json, done)")
    problem = StudyProblem(loaded)
    if data.get("study_sha256") != study_digest(problem):
        raise InvalidInputError(
            "result",
            str(result),
            f"a result folder of this study ({loaded.name!r}); its checkpoint belongs to another study or EMLA set",
        )
    return problem.unpack(np.asarray(data["z"], dtype=float))[1]


def evaluate(
    study: Study | str | Path, lengths: Lengths, trajectory: str = "fixed", result: str | Path | None = None
) -> DesignEvaluation:
    """Evaluate a design on every task of a study: energies, margins, violations (module docstring).

    Args:
        study: A loaded study, a shipped study name or a study file.
        lengths: The design Xi [m] (:data:`Lengths`).
        trajectory: ``"fixed"`` (the inverse-kinematics start at these lengths), ``"reoptimize"``
            (the trajectory re-optimised with the lengths fixed; needs CasADi) or ``"optimum"`` (the
            trajectory of ``result``'s optimum).
        result: With ``"optimum"``: the result folder of an optimisation of this study.

    Raises:
        InvalidInputError: An unknown ``trajectory``, lengths of the wrong shape, a design outside
            the model's domain (a chain that cannot close), or with ``"optimum"`` a folder that is not a
            finished optimisation of this study, naming the field.
        BackendUnavailableError: ``"reoptimize"`` without CasADi.

    """
    if trajectory not in TRAJECTORIES:
        raise InvalidInputError("trajectory", trajectory, f"one of {list(TRAJECTORIES)}")
    if result is not None and trajectory != "optimum":
        raise InvalidInputError("result", str(result), 'given only with trajectory="optimum"')
    from hiab_sim.study.analysis.cross_evaluation import fixed_lengths_optimum, task_alone
    from hiab_sim.study.report.design_check import design_summary, fine_problem
    from hiab_sim.study.report.energy_section import design_energy

    loaded = _as_study(study)
    design = as_design(loaded.model, lengths)
    planned = _optimum_coefficients(loaded, result) if trajectory == "optimum" else None
    tasks = []
    for k, task in enumerate(loaded.tasks):
        alone = task_alone(loaded, k)  # the task's NLP as a study of its own
        problem = alone.problems[0]
        message = None
        if trajectory == "fixed":
            z = problem.initial_point(design)
        elif planned is not None:
            z = problem.initial_point(design, planned[k])
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

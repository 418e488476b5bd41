"""One optimisation run end to end: study -> starts -> SQP -> result folder (JSON, NPZ, figures)."""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TextIO

from hiab_sim.atomic_io import write_atomic
from hiab_sim.errors import BackendUnavailableError, ConfigError, SolverError
from hiab_sim.results.schema import Result
from hiab_sim.study import run_safety
from hiab_sim.study.analysis.codesign import run_codesign
from hiab_sim.study.analysis.cross_evaluation import cross_evaluation
from hiab_sim.study.nlp.problem import make_problem
from hiab_sim.study.report.analysis_sections import analysis_sections
from hiab_sim.study.report.result_folder import build_result, write_results
from hiab_sim.study.solvers.feasibility import feasible_starts, moved_start_phase, phase_lines
from hiab_sim.study.solvers.slsqp import (
    SolveResult,
    check_checkpoint,
    solve,
    study_digest,
)
from hiab_sim.study.spec.study_file import Study, load_study


@dataclass(frozen=True)
class RunOutput:
    """What a run wrote: the folder, the result (as in its result.json), the figure paths, earlier outputs removed."""

    folder: Path
    result: Result
    figures: list[Path]
    removed: tuple[Path, ...] = ()


def run_study(
    study: Study | str | Path | None,
    out: str | Path,
    starts: int = 1,
    resume: bool = False,
    id_path: str | None = None,
    progress: TextIO | None = sys.stderr,
    figures: bool = True,
    force: bool = False,
    cross: bool = True,
) -> RunOutput:
    """Optimise a study and write its result folder.

    Bad input (study, ``starts`` not an integer >= 1, unreachable reference, infeasible start, with
    ``resume`` a checkpoint of another study, ID path or start) raises before anything is written. A fresh run (no
    ``resume``) deletes every output of earlier runs; a folder of another study is refused unless
    ``force`` (:mod:`hiab_sim.study.run_safety`). Every study, of one task or several, is one
    :class:`~hiab_sim.study.nlp.problem.StudyProblem`, reported by
    :func:`~hiab_sim.study.report.result_folder.build_result` with its buildable design, feasibility
    phases and sensitivities; a study of several tasks adds the cross-evaluation of
    :mod:`hiab_sim.study.analysis.cross_evaluation` unless ``cross`` is False. A failure of SLSQP on the
    study's own start raises :class:`SolverError` after its checkpoint (the partial history) is
    on disk; failures of extra starts are reported (``multistart.failed_starts``).
    """
    t0 = time.perf_counter()
    starts = run_safety.check_starts(starts)
    if not isinstance(study, Study):
        study = load_study(study)
    codesign = None
    if study.energy.transmission is not None:  # mounting x transmission catalogue, then the best
        codesign, emlas = run_codesign(study, progress=progress)
        study = replace(study, emlas=emlas)
    problem = make_problem(study, id_path)
    points, phases = feasible_starts(problem, starts)
    initials = [problem.unpack(z)[0] for z in points]
    moved = moved_start_phase(problem, problem.initial_point(study.initial_lengths))
    phases = [moved, *phases] if moved is not None else phases
    folder = Path(out)
    run_safety.check_folder(folder, study_digest(problem), resume, force)
    if resume:
        for k, initial in enumerate(initials):
            check_checkpoint(problem, initial, folder, k)
    owner = run_safety.owner_record(study.path, study.name, study_digest(problem), starts)
    removed = run_safety.claim_folder(folder, owner, resume)
    if removed and progress is not None:
        progress.write(f"removed {len(removed)} output file(s) of an earlier run in {folder}\n")
    results: list[SolveResult] = []
    for k, initial in enumerate(initials):
        try:
            if progress is not None:
                for phase in phases:
                    if phase.start == k:
                        progress.write("\n".join(phase_lines(phase)) + "\n")
            results.append(solve(problem, initial, start=k, out=folder, resume=resume, progress=progress, z0=points[k]))
        except SolverError as error:
            if k == 0:
                raise
            if progress is not None:
                progress.write(f"[start {k}] {error}\n")
            failed = SolveResult(start=k, initial_lengths=initial, z0=points[k], z=points[k])
            failed.success = False
            failed.message = str(error)
            results.append(failed)
    evaluation = None
    if cross and problem.n_tasks > 1:  # designs x tasks: each task's own optimum against the study's
        try:
            evaluation = cross_evaluation(problem, results[0].z)
        except (BackendUnavailableError, ConfigError) as error:  # CasADi (IPOPT) is an optional dependency
            if progress is not None:
                progress.write(f"no cross-evaluation: {error}\n")
    result, arrays, checks = build_result(problem, results, time.perf_counter() - t0, evaluation)
    if codesign is not None:
        result = replace(result, codesign=codesign)
    crane_file = study.crane_file
    # a crane (machine) file, not a preset name, is copied next to the result
    copy = "crane.yaml" if study.crane_description is not None else "machine.yaml"
    if crane_file is not None and not (crane_file.shipped and crane_file.label == study.crane_source):
        write_atomic(folder / copy, crane_file.read_bytes())
        result = replace(result, crane=copy, crane_source=study.crane_source)
    crane_label = study.crane_source if result.crane != copy else str(folder / copy)
    result = replace(result, **analysis_sections(problem, results[0].z, result, crane_label, phases))
    write_results(folder, result, arrays)
    paths: list[Path] = []
    if figures:
        from hiab_sim.study.figures.cross_evaluation import cross_figure
        from hiab_sim.study.figures.optimisation import write_figures

        paths = write_figures(folder, problem.study.crane_description, problem.emlas, result, arrays, checks)
        if result.cross_evaluation is not None:
            paths.append(folder / "cross_evaluation.png")
            cross_figure(result.cross_evaluation, paths[-1])
    return RunOutput(folder, result, paths, tuple(removed))

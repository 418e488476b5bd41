"""The ``buildable`` section of a result: the optimum rounded to the tolerance and re-checked three ways.

1. the crane's own length check (:func:`hiab_sim.crane.mechanism.check_lengths`) over the buildable
   working range (:func:`hiab_sim.crane.tolerance.buildable_crane`), what ``hiab-sim mjcf
   --stroke-margin M --lengths ...`` runs;
2. every design within +-tolerance of the optimum (the 64 corners of the box, the nominal and the
   rounded design) on the working-range and mounting rows (:func:`hiab_sim.crane.tolerance.check_tolerance`);
3. the fine-grid re-check of the rounded lengths with the optimal trajectory: the nominal NLP rows
   (tracking bands, EMLA envelope, strokes, joints, working range) of a study whose crane has the
   buildable range, on the other inverse-dynamics path, with its energy: every task on its fine
   grid, the energy weighted by the tasks' weights and the violation the worst over the tasks.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane import mechanism
from hiab_sim.crane.description import LinkLengths
from hiab_sim.crane.mounting import MountingSpace
from hiab_sim.crane.tolerance import buildable_crane, check_tolerance, design_margins, range_cost_deg
from hiab_sim.errors import InvalidInputError
from hiab_sim.results.analysis_sections import Buildable, RoundedCheck
from hiab_sim.results.design_values import crane_lengths, design_words
from hiab_sim.results.schema import DesignSummary
from hiab_sim.study.analysis.buildable import rounded_design
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.report.design_check import design_summary, other_path
from hiab_sim.study.report.weighted import weighted_summary
from hiab_sim.study.spec.study import Study


def rounded_point(problem: StudyProblem, z: Array) -> tuple[LinkLengths, Array]:
    """The rounded lengths of the optimum z and the point (rounded Xi, optimal trajectory)."""
    lengths, _ = problem.unpack(z)
    study = problem.study
    rounded = rounded_design(
        crane_lengths(lengths), study.build.tolerance, np.asarray(study.bounds.xi_low), np.asarray(study.bounds.xi_up)
    )
    return rounded, problem.with_lengths(z, rounded)


def mjcf_command(study_crane: str, stroke_margin: float, lengths: LinkLengths) -> str:
    """The ``hiab-sim mjcf`` command that exports a rounded design."""
    xi = ",".join(f"{v:g}" for v in lengths.as_array())
    return f"hiab-sim mjcf --crane {study_crane} --stroke-margin {stroke_margin:g} --lengths {xi}"


def rounded_recheck(problem: StudyProblem, study: Study, z_rounded: Array, optimum: DesignSummary) -> dict[str, Any]:
    """The fine-grid re-check of a rounded design z_rounded on the other ID path: the ``Buildable`` fields it fills.

    ``study`` is the one the re-check's nominal rows come from (a crane file's with its buildable
    range); every task on its fine grid, the energy weighted by the tasks' weights, the violation the
    worst over the tasks (passed at <= 1e-6 scaled), the energy change against ``optimum``'s.
    """
    fine = StudyProblem(
        study,
        emlas=problem.emlas,
        id_path=other_path(problem.id_path),
        tightened=False,
        fine=True,
        cost_scales=[p.cost_scale for p in problem.problems],
    )
    names = [task.name for task in study.tasks]
    summaries = [design_summary(p, fine.task_z(z_rounded, k)).summary for k, p in enumerate(fine.problems)]
    summary = weighted_summary(summaries, fine.weights, names)
    worst = summary.worst_constraint
    return {
        "recheck": RoundedCheck(
            summary.max_violation <= 1e-6,
            worst.name if worst is not None else "none",
            summary.max_violation,
            "scaled max violation",
        ),
        "recheck_id_path": fine.id_path,
        "recheck_grid_points": sum(len(p.times) for p in fine.problems),
        "net_electrical_energy_J": summary.net_electrical_energy_J,
        "drawn_energy_summed_drives_J": summary.drawn_energy_summed_drives_J,
        "net_energy_change_vs_optimum_J": summary.net_electrical_energy_J - optimum.net_electrical_energy_J,
    }


def buildable_section(problem: StudyProblem, z: Array, optimum: DesignSummary, crane_label: str) -> Buildable:
    """Round the optimum z to the study's tolerance and re-check it (module docstring)."""
    study = problem.study
    t, margin = study.build.tolerance, study.build.stroke_margin
    rounded, z_rounded = rounded_point(problem, z)
    short = buildable_crane(study.crane, margin)
    try:
        mechanism.check_lengths(short, rounded)
        crane_check = RoundedCheck(True, "check_lengths over the buildable working range", 0.0, "m")
    except InvalidInputError as error:
        crane_check = RoundedCheck(False, str(error), float("nan"), "m")
    lengths = crane_lengths(problem.unpack(z)[0])
    space = study.mounting
    assert space is None or isinstance(space, MountingSpace)  # a crane file's study reads the crane form
    tol = check_tolerance(design_margins(short, space), lengths, t)
    label, row, value = tol.worst()
    tolerance_check = RoundedCheck(tol.ok, f"{row} at the {label} design", value, "m")
    return Buildable(
        tolerance_m=t,
        stroke_margin_m=margin,
        range_given_up_deg={k: tuple(v) for k, v in range_cost_deg(study.crane, margin).items()},
        lengths=rounded,
        crane_check=crane_check,
        tolerance_check=tolerance_check,
        mjcf_command=mjcf_command(crane_label, margin, rounded),
        **rounded_recheck(problem, replace(study, crane_description=short), z_rounded, optimum),
    )


def buildable_line(b: Buildable) -> str:
    """One stdout line: the rounded design, its checks and energy."""
    check = "crane check" if isinstance(b.lengths, LinkLengths) else "stroke check"
    ok = all(c.passed for c in (b.crane_check, b.tolerance_check, b.recheck))
    return (
        f"buildable (rounded to {b.tolerance_m * 1e3:g} mm, stroke margin {b.stroke_margin_m * 1e3:g} mm): "
        f"{design_words(b.lengths, 'g')}  "
        f"net energy {b.net_electrical_energy_J / 1e3:.3f} kJ ({b.net_energy_change_vs_optimum_J:+.1f} J vs optimum); "
        f"{'checks passed' if ok else 'CHECK FAILED'}: {check} {'ok' if b.crane_check.passed else 'FAILED'}, "
        f"+-{b.tolerance_m * 1e3:g} mm worst margin {b.tolerance_check.margin * 1e3:.3f} mm, "
        f"fine-grid re-check max violation {b.recheck.margin:.1e}"
    )

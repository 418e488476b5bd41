"""The analysis sections of a result (buildable design, feasibility phase, sensitivities) and their stdout lines."""

from __future__ import annotations

from typing import Any

import numpy as np

from hiab_sim.results.analysis_sections import FeasibilityPhase
from hiab_sim.results.schema import Result
from hiab_sim.study.analysis.sensitivity import sensitivity
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.report.buildable_section import buildable_line, buildable_section
from hiab_sim.study.report.machine_buildable import machine_buildable_section
from hiab_sim.study.solvers.feasibility import phase_lines

#: Multipliers printed to stdout (all are in result.json).
PRINTED_MULTIPLIERS = 6


def analysis_sections(
    problem: StudyProblem, z: np.ndarray, result: Result, crane_label: str, phases: list[FeasibilityPhase]
) -> dict[str, Any]:
    """Keyword arguments for ``dataclasses.replace(result, ...)``: buildable, feasibility, sensitivity."""
    return {
        "buildable": machine_buildable_section(problem, z, result.optimal, crane_label)
        if problem.study.crane_description is None
        else buildable_section(problem, z, result.optimal, crane_label),
        "feasibility": tuple(phases) if phases else None,
        "sensitivity": sensitivity(problem, z),
    }


def extra_lines(r: Result) -> list[str]:
    """Stdout lines: the feasibility phases, the buildable design and the largest multipliers."""
    lines: list[str] = []
    for phase in r.feasibility or ():
        lines += phase_lines(phase)
    if r.buildable is not None:
        lines.append(buildable_line(r.buildable))
        lines.append(f"  export: {r.buildable.mjcf_command}")
    if r.sensitivity is not None and r.sensitivity.multipliers:
        s = r.sensitivity
        lines.append(
            f"sensitivity (KKT residual {s.kkt_residual:.1e}): decrease of {s.objective} "
            f"({s.objective_value:.6g} {s.objective_unit}) per unit the limit is relaxed"
        )
        for m in s.multipliers[:PRINTED_MULTIPLIERS]:
            lines.append(
                f"  {m.constraint}: {m.objective_decrease_per_unit:.4g} {s.objective_unit} "
                f"({m.percent_per_unit:.3f} % of the optimum) per {m.unit}"
            )
    return lines

"""Transmission co-design: the mounting optimised for every combination of a (G, rho) catalogue.

The study's ``transmission`` key lists discrete (gear ratio G, screw lead rho) options per actuator
(:class:`~hiab_sim.study.spec.energy.TransmissionCatalogue`); actuators not listed keep the EMLA
file's. Every combination, plus the EMLA file's own transmission (the reference: mounting alone),
is a separate NLP of the study (same objective, constraints and duty; the transmission changes the
force-speed trade k = 2 pi G / rho of eq. ``torque_force``, hence the envelope, the copper losses and
the thermal rows), solved from the study's start in a process pool. A combination whose start
violates a constraint (e.g. a lead too long for the peak force) is listed as ``infeasible start``.

Each optimum is evaluated on the fine grid (nominal bands) by
:func:`hiab_sim.study.report.energy_section.design_energy`: exact battery energy, costf2 and the thermal
margins. The best combination is the converged one (max violation <= ``FEASIBLE``, thermal margins
>= 0) of least exact objective (any registered objective in its own unit: battery energy [J],
costf2 [W^2 s], ...; weighted over the study's tasks); the saving of the co-design
is compared with the reference row's, both relative to the initial design with the file's
transmission.
"""

from __future__ import annotations

import itertools
import os
import sys
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from typing import TextIO

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaSet
from hiab_sim.errors import InvalidInputError, SolverError
from hiab_sim.percent import saving_percent
from hiab_sim.results.energy_sections import Codesign, CodesignRow, DesignEnergy, TransmissionChoice
from hiab_sim.study.nlp.objectives import exact_value
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.report.energy_section import design_energy
from hiab_sim.study.solvers.slsqp import check_start, solve
from hiab_sim.study.spec.study_file import Study

#: Largest scaled violation of a converged combination that counts as feasible.
FEASIBLE = 1e-6

Combination = dict[str, TransmissionChoice]


def combinations(study: Study) -> list[Combination]:
    """The EMLA file's own transmission first, then every catalogue combination not equal to it."""
    catalogue = study.energy.transmission
    if catalogue is None:
        raise InvalidInputError("transmission", None, "the study must give a transmission catalogue")
    own = {p.name: TransmissionChoice(p.gear_ratio, p.screw_lead) for p in study.emlas}
    names = [name for name, _ in catalogue.options]
    out = [own]
    for choice in itertools.product(*(opts for _, opts in catalogue.options)):
        combo = dict(own)
        combo.update({n: TransmissionChoice(o.gear_ratio, o.screw_lead) for n, o in zip(names, choice, strict=True)})
        if combo not in out:
            out.append(combo)
    return out


def with_transmission(emlas: EmlaSet, combo: Combination) -> EmlaSet:
    """The EMLA set with each actuator's (G, rho) replaced by the combination's."""
    return EmlaSet(
        *(replace(p, gear_ratio=combo[p.name].gear_ratio, screw_lead=combo[p.name].screw_lead) for p in emlas),
        battery=emlas.battery,
    )


def _min_margin(e: DesignEnergy) -> float | None:
    if not e.thermal:
        return None
    return min(min(t.torque_margin, t.temperature_margin_K / 100.0) for t in e.thermal.values())


@dataclass(frozen=True)
class StudyEnergy:
    """A design's fine-grid energies, weighted over the study's tasks, and its least thermal margin."""

    battery_energy_J: float
    costf2_W2s: float
    objective_value: float  # the study's objective, exact (unsmoothed) where it has an exact form [its unit]
    min_thermal_margin: float | None


def study_energy(fine: StudyProblem, z: Array) -> StudyEnergy:
    """Battery energy [J], costf2 [W^2 s] and the objective over the tasks' fine grids (weighted), thermal worst."""
    battery = costf2 = objective = 0.0
    margins = []
    for k, (w, p) in enumerate(zip(fine.weights, fine.problems, strict=True)):
        ev = p.evaluate(fine.task_z(z, k))
        e = design_energy(p, ev)
        battery += w * e.battery_energy_J
        costf2 += w * e.costf2_W2s
        objective += w * exact_value(p.objective, ev)
        margins.append(_min_margin(e))
    known = [m for m in margins if m is not None]
    return StudyEnergy(float(battery), float(costf2), float(objective), min(known) if known else None)


def solve_combination(study: Study, combo: Combination) -> CodesignRow:
    """Optimise the mounting of ``study`` with the transmission ``combo``; one table row (never raises)."""
    emlas = with_transmission(study.emlas, combo)
    try:
        problem = StudyProblem(study, emlas=emlas)
        z0 = problem.initial_point(study.initial_lengths)
        check_start(problem, z0)
    except InvalidInputError as error:
        return CodesignRow(combo, "infeasible start", str(error))
    fine = StudyProblem(
        study, emlas=emlas, tightened=False, fine=True, cost_scales=[p.cost_scale for p in problem.problems]
    )
    e0 = study_energy(fine, z0)
    try:
        result = solve(problem, study.initial_lengths, progress=None)
    except (SolverError, InvalidInputError) as error:
        return CodesignRow(combo, "solver failed", str(error), initial_battery_energy_J=e0.battery_energy_J)
    e1 = study_energy(fine, result.z)
    return CodesignRow(
        combo,
        "converged",
        result.message,
        initial_battery_energy_J=e0.battery_energy_J,
        battery_energy_J=e1.battery_energy_J,
        costf2_W2s=e1.costf2_W2s,
        objective_value=e1.objective_value,
        objective_unit=problem.objective.unit,
        lengths=problem.unpack(result.z)[0],
        max_violation=problem.max_violation(result.z),
        min_thermal_margin=e1.min_thermal_margin,
        iterations=result.iterations,
        wall_time_s=result.wall_time,
    )


def _score(row: CodesignRow) -> float:
    feasible = (
        row.status == "converged"
        and row.max_violation is not None
        and row.max_violation <= FEASIBLE
        and (row.min_thermal_margin is None or row.min_thermal_margin >= 0.0)
    )
    value = row.objective_value
    return float(value) if feasible and value is not None else float("inf")


def run_codesign(
    study: Study, workers: int | None = None, progress: TextIO | None = sys.stderr
) -> tuple[Codesign, EmlaSet]:
    """Solve every combination (``workers`` processes; default: the CPUs, at most the combinations).

    Returns the ``codesign`` section and the EMLA set of the best combination.

    Raises:
        SolverError: No combination converged to a feasible, thermally admissible optimum.

    """
    combos = combinations(study)
    n = min(len(combos), workers or os.cpu_count() or 1)
    if progress is not None:
        progress.write(f"co-design: {len(combos)} transmission combinations on {n} processes\n")
    if n > 1:
        with ProcessPoolExecutor(max_workers=n) as pool:
            rows = list(pool.map(solve_combination, [study] * len(combos), combos))
    else:
        rows = [solve_combination(study, c) for c in combos]
    objective = study.energy.objective
    scores = [_score(r) for r in rows]
    best = int(np.argmin(scores))
    if not np.isfinite(scores[best]):
        raise SolverError("co-design: no transmission combination reached a feasible optimum")
    ref, top = rows[0], rows[best]
    e00 = ref.initial_battery_energy_J
    if e00 is None or ref.battery_energy_J is None or top.battery_energy_J is None:
        raise SolverError(f"co-design: the EMLA file's own transmission did not converge: {ref.message}")
    codesign = Codesign(
        objective=objective,
        note=(
            "mounting optimised for every transmission combination (row 0: the EMLA file's own, mounting alone); "
            "fine-grid exact battery energy; savings relative to the initial design with the file's transmission"
        ),
        rows=tuple(rows),
        best=best,
        reference=0,
        initial_battery_energy_J=e00,
        mounting_only_battery_energy_J=ref.battery_energy_J,
        codesign_battery_energy_J=top.battery_energy_J,
        mounting_only_saving_percent=saving_percent(e00, ref.battery_energy_J),
        codesign_saving_percent=saving_percent(e00, top.battery_energy_J),
        extra_saving_J=ref.battery_energy_J - top.battery_energy_J,
    )
    return codesign, with_transmission(study.emlas, combos[best])


def codesign_lines(c: Codesign) -> list[str]:
    """The co-design table as printed by ``hiab-sim optimize``."""
    lines = [f"co-design ({c.objective}): {len(c.rows)} transmission combinations (G, rho mm), exact battery energy:"]
    for k, r in enumerate(c.rows):
        trans = " ".join(f"{n} {t.gear_ratio:g}/{t.screw_lead * 1e3:g}" for n, t in r.transmission.items())
        mark = " <- best" if k == c.best else (" (mounting alone)" if k == c.reference else "")
        if r.battery_energy_J is None:
            lines.append(f"  [{k}] {trans}: {r.status}: {r.message[:100]}{mark}")
            continue
        margin = "n/a" if r.min_thermal_margin is None else f"{r.min_thermal_margin:.3f}"
        lines.append(
            f"  [{k}] {trans}: {r.battery_energy_J / 1e3:.4f} kJ (start {(r.initial_battery_energy_J or 0) / 1e3:.4f}),"
            f" max violation {r.max_violation:.1e}, min thermal margin {margin}{mark}"
        )
    lines.append(
        f"co-design saves {c.codesign_saving_percent:.2f} % of the battery energy, mounting alone "
        f"{c.mounting_only_saving_percent:.2f} % ({c.extra_saving_J:.1f} J more per cycle)"
    )
    return lines

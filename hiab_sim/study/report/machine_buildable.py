"""The ``buildable`` section of a machine file's result: the optimum rounded to the tolerance, re-checked three ways.

As :mod:`hiab_sim.study.report.buildable_section` for a crane file, through the machine description:

1. the rounded design's strokes over the buildable working range (the working range within the
   file design's range that keeps ``build.stroke_margin`` of stroke at both ends,
   :meth:`~hiab_sim.study.machines.machine_model.MachineModel.buildable_ranges`; as the crane's
   ``check_lengths`` over its buildable crane): on a grid of each stroke chain's joint,
   min(x, stroke - x, Lc - x) >= 0 [m] (the rod stays in its barrel) by the closed-form loop
   closure, interior extremes of a four-bar's stroke included;
2. every design within +-tolerance of the optimum (the 2^n_xi corners of the box, the nominal
   and the rounded design) on the same stroke rows and, with a ``mounting`` section, on the
   mounting rows (:mod:`hiab_sim.machine.mounting`);
3. the fine-grid re-check of the rounded design with the optimal trajectory on the other
   inverse-dynamics path: the nominal NLP rows and the energy, every task on its fine grid.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.machine.design import MachineDesign
from hiab_sim.results.analysis_sections import Buildable, RoundedCheck
from hiab_sim.results.schema import DesignSummary
from hiab_sim.study.analysis.buildable import buildable_working_range, rounded_values
from hiab_sim.study.constraints.mounting_rows import study_mounting_margins
from hiab_sim.study.machines.machine_model import MachineModel
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.report.buildable_section import rounded_recheck

#: Grid points per stroke chain's joint range of the stroke check [-].
STROKE_GRID = 201


def stroke_margin(
    model: MachineModel, design: MachineDesign, ranges: tuple[tuple[float, float], ...]
) -> tuple[float, str]:
    """Smallest of x, stroke - x and Lc - x [m] over the stroke chains' ranges' grid, and the row it is."""
    grid = np.zeros((STROKE_GRID * len(ranges), len(model.joint_names)))
    mid = [0.5 * (lo + hi) for lo, hi in model.joint_ranges()]
    grid[:] = mid
    for c, (j, (lo, hi)) in enumerate(zip(model.stroke_joints, ranges, strict=True)):
        grid[c * STROKE_GRID : (c + 1) * STROKE_GRID, j] = np.linspace(lo, hi, STROKE_GRID)
    rows = model.stroke_margins(design, grid)  # x, Lc - x, stroke - x per stroke chain
    worst, name = math.inf, "none"
    for c, chain in enumerate(model.stroke_chains):
        block = slice(c * STROKE_GRID, (c + 1) * STROKE_GRID)  # a chain's stroke depends on its own joint
        x, rod, top = rows[block, 3 * c], rows[block, 3 * c + 1], rows[block, 3 * c + 2]
        for label, values in (
            (f"{chain}.x >= 0", x),
            (f"{chain}.x <= stroke", top),
            (f"{chain}.x <= rod length", rod),
        ):
            if float(np.min(values)) < worst:
                worst, name = float(np.min(values)), label
    return worst, name


def machine_buildable_section(problem: StudyProblem, z: Array, optimum: DesignSummary, label: str) -> Buildable:
    """Round a machine study's optimum z to the tolerance and re-check it (module docstring)."""
    study = problem.study
    model = study.model
    assert isinstance(model, MachineModel)
    t, margin = study.build.tolerance, study.build.stroke_margin
    optimal, _ = problem.unpack(z)
    assert isinstance(optimal, MachineDesign)
    low, up = np.asarray(study.bounds.xi_low), np.asarray(study.bounds.xi_up)
    rounded = model.design(rounded_values(optimal.as_array(), t, low, up))
    ranges = buildable_working_range(study, problem.problems[0].working)
    value, row = stroke_margin(model, rounded, ranges)
    stroke_check = RoundedCheck(value >= 0.0, f"strokes over the buildable working range: {row}", value, "m")
    signs = list(itertools.product((-1.0, 1.0), repeat=len(optimal.values)))
    corners = [optimal.as_array() + t * np.asarray(sign) for sign in signs]
    # a corner named by its signs in the decision variables' order, as the crane file's (crane/tolerance.py)
    corner_names = ["corner " + "".join("+" if v > 0 else "-" for v in sign) for sign in signs]
    mounting = study_mounting_margins(study)
    worst = (math.inf, "none", "nominal")
    for where, values in [("nominal", optimal.as_array()), ("rounded", rounded.as_array())] + [
        (name, v) for name, v in zip(corner_names, corners, strict=True)
    ]:
        design = model.design(values)
        m, name = stroke_margin(model, design, ranges)
        if mounting is not None:
            name, m = min((name, m), mounting(design).worst(), key=lambda row: row[1])
        if m < worst[0]:
            worst = (m, name, where)
    tolerance_check = RoundedCheck(worst[0] >= 0.0, f"{worst[1]} at the {worst[2]} design", worst[0], "m")
    full = model.joint_ranges()
    given_up: dict[str, tuple[float, ...]] = {
        chain: (math.degrees(r[0] - full[j][0]), math.degrees(full[j][1] - r[1]))
        for chain, j, r in zip(model.stroke_chains, model.stroke_joints, model.buildable_ranges(margin), strict=True)
    }
    items = " ".join(f"{k}={v:g}" for k, v in zip(rounded.names, rounded.values, strict=True))
    return Buildable(
        tolerance_m=t,
        stroke_margin_m=margin,
        range_given_up_deg=given_up,
        lengths=rounded,
        crane_check=stroke_check,
        tolerance_check=tolerance_check,
        mjcf_command=f"hiab-sim mjcf --machine {label} --design {items}",
        **rounded_recheck(problem, study, problem.with_lengths(z, rounded), optimum),
    )

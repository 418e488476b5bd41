"""An infeasible study names every limit its least violation is tied on, not only the first row of them.

Minimising the largest violation spreads it: on a crane whose main-boom EMLA overheats at every mounting,
the phase trades the winding temperature against the tracking band until both are out by as much, and the
row named first (a tracking row) is not the limit to change. Every tied block is named, in one line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml
from machine_result_helper import EXCAVATOR_STUDY, joint_csv

from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers.feasibility import describe_binding
from hiab_sim.study.spec.study_file import load_study


def _problem(folder: Path) -> StudyProblem:
    """The small excavator study with a duty (so it has thermal rows)."""
    joint_csv(folder / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump({**EXCAVATOR_STUDY, "duty": {"rest_time": 2.0, "hold": "brake"}}))
    return StudyProblem(load_study(path))


def test_tied_blocks_are_all_named_in_one_line(tmp_path: Path) -> None:
    """A tracking row and a winding-temperature row out by 0.5 (scaled) both named; a row out by less is not."""
    problem = _problem(tmp_path)
    names = problem.constraint_names
    tracking = next(k for k, n in enumerate(names) if n.startswith("tracking.position"))
    winding = next(k for k, n in enumerate(names) if n.startswith("thermal.") and n.endswith("winding temperature"))
    lesser = next(k for k, n in enumerate(names) if n.startswith("working_range."))
    g = np.ones(len(names))
    g[[tracking, winding]] = -0.5
    g[lesser] = -0.3
    text = describe_binding(problem, g)
    assert "\n" not in text
    assert text.startswith(names[tracking].split(" at t=")[0]) and "by 50 % of the band" in text
    assert f"; as far out: {names[winding]} violated by 50 K" in text
    assert "working_range" not in text

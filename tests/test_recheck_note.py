"""The re-check's note states the grid it ran on: ``grid.fine_factor`` times the collocation grid, not always 10x."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from hiab_sim.results.read import read_result
from hiab_sim.study.report.weighted import weighted_recheck


def test_recheck_note_names_the_studys_fine_factor(excavator_result: Path) -> None:
    """The small excavator study re-checks on 4 x 12 intervals (fine_factor 4): the note says 4x, the grid has 49."""
    recheck = json.loads((excavator_result / "result.json").read_text())["recheck"]
    assert recheck["grid_points"] == 4 * 12 + 1
    assert recheck["note"].startswith("optimal design re-evaluated on the 4x finer grid")


def test_a_mix_recheck_note_names_the_fine_factor(excavator_result: Path) -> None:
    """Two tasks' re-checks combined: the note carries the study's factor (here 4)."""
    one = read_result(excavator_result).recheck
    mixed = weighted_recheck([one, one], np.array([1.0, 2.0]), ["a", "b"], 4)
    assert "its 4x finer grid" in mixed.note and "10x" not in mixed.note

"""The default study end to end: what issue 6 says its optimum must show (about 5 s)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from hiab_sim.study.run import run_study


@pytest.fixture(scope="module")
def result(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Run optimize/xs031_spiral.yaml with three feasible starts (no figures, no video)."""
    out: Path = tmp_path_factory.mktemp("xs031_spiral")
    return run_study(None, out, starts=3, progress=None, figures=False).result


def test_default_optimum_is_a_successful_feasible_improvement(result: dict[str, Any]) -> None:
    """SLSQP reports success, the optimum violates no constraint and uses strictly less energy."""
    assert result["solver"]["success"] is True
    assert result["solver"]["max_violation_scaled"] <= 1e-6
    assert result["solver"]["iterations"] <= 100
    assert result["optimal"]["net_electrical_energy_J"] < result["initial"]["net_electrical_energy_J"]
    assert result["optimal"]["cost_W2s"] < result["initial"]["cost_W2s"]


def test_default_optimum_holds_on_the_fine_grid_with_the_other_path(result: dict[str, Any]) -> None:
    """The independent re-check (10x finer grid, analytic ID) finds no violation and tracking inside the band."""
    recheck = result["recheck"]
    assert recheck["id_path"] == "analytic"
    assert recheck["grid_points"] == 251
    assert recheck["max_violation_scaled"] <= 1e-6
    assert recheck["tracking_error"]["position_m"] <= 1e-3
    assert recheck["force_difference_between_paths_N"] <= 1e-6


def test_default_starts_reach_one_optimum(result: dict[str, Any]) -> None:
    """Three feasible starts converge to the same link lengths within 1e-4 m."""
    multistart = result["multistart"]
    assert len(multistart["starts"]) == 3
    assert multistart["same_optimum"] is True
    xi = [
        np.array([*s["optimal_lengths"]["lift"].values(), *s["optimal_lengths"]["tilt"].values()])
        for s in multistart["starts"]
    ]
    assert max(float(np.max(np.abs(a - xi[0]))) for a in xi) <= 1e-4


def test_saving_decomposes_into_lengths_and_trajectory(result: dict[str, Any]) -> None:
    """The lengths alone (on the initial trajectory) save energy, and the parts add up to the total."""
    improvement = result["improvement"]
    saved = improvement["net_energy_saved_J"]
    assert saved > 0.0
    decomposition = improvement["decomposition"]
    assert decomposition["from_lengths_J"] > 0.0
    total = decomposition["from_lengths_J"] + decomposition["from_trajectory_J"] + decomposition["interaction_J"]
    assert total == pytest.approx(saved, rel=1e-9)

"""The default study end to end: what its optimum must show (one start; three starts under -m slow)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from result_checks import four_designs

from hiab_sim.emla import load_emla_set
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import Result
from hiab_sim.study.nlp.task_setup import duty_options
from hiab_sim.study.run import RunOutput, run_study
from hiab_sim.study.spec.study_file import load_study

#: End-to-end runs of whole studies and commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> RunOutput:
    """Run optimize/xs031_spiral.yaml from its own start (no figures, no video)."""
    return run_study(None, tmp_path_factory.mktemp("xs031_spiral"), progress=None, figures=False)


@pytest.fixture(scope="module")
def result(run: RunOutput) -> Result:
    """The result as read back from the folder's result.json."""
    written = read_result(run.folder)
    assert written == run.result
    return written


def test_default_optimum_is_a_successful_feasible_improvement(result: Result) -> None:
    """SLSQP reports success, the optimum violates no constraint and uses strictly less energy."""
    assert result.solver.success is True
    assert result.solver.max_violation_scaled <= 1e-6
    assert result.solver.iterations <= 100
    assert result.optimal.net_electrical_energy_J < result.initial.net_electrical_energy_J
    assert result.optimal.cost_W2s < result.initial.cost_W2s


def test_default_optimum_holds_on_the_fine_grid_with_the_other_path(result: Result) -> None:
    """The independent re-check (10x finer grid, analytic ID) finds no violation and tracking inside the band."""
    recheck = result.recheck
    assert recheck.id_path == "analytic"
    assert recheck.grid_points == 251
    assert recheck.max_violation_scaled <= 1e-6
    assert recheck.tracking_error.position_m <= 1e-3
    assert recheck.force_difference_between_paths_N <= 1e-6


@pytest.mark.e2e
def test_default_starts_reach_one_optimum(tmp_path: Path) -> None:
    """Three feasible starts converge to the same link lengths within 1e-4 m (a full multi-start study)."""
    multistart = run_study(None, tmp_path, starts=3, progress=None, figures=False).result.multistart
    assert len(multistart.starts) == 3
    assert multistart.same_optimum is True
    xi = []
    for start in multistart.starts:
        assert start.optimal_lengths is not None
        xi.append(start.optimal_lengths.as_array())
    assert max(float(np.max(np.abs(a - xi[0]))) for a in xi) <= 1e-4
    assert len({s.initial_lengths for s in multistart.starts}) == 3  # three different starts


def test_saving_decomposes_into_lengths_and_trajectory(run: RunOutput, result: Result) -> None:
    """The lengths alone save energy, and the reported parts equal a direct evaluation of the four designs.

    The four (lengths, trajectory) combinations are re-evaluated from the folder (lengths of
    result.json, joints of trajectory.npz) by the analytic ID path (the run used MuJoCo); the
    interaction is evaluated as E10 + E01 - E00 - E11, not as the remainder of the total.
    """
    study, emlas = load_study(), load_emla_set()
    duty = duty_options(study, emlas, study.tasks[0].reference.duration)  # hot windings, the brake at rest
    e = {k: net for k, (net, _) in four_designs(run.folder, result, study.crane, emlas, duty).items()}
    e00, e11 = e["initial", "initial"], e["optimal", "optimal"]
    e10, e01 = e["optimal", "initial"], e["initial", "optimal"]
    d = result.improvement.decomposition
    assert result.improvement.net_energy_saved_J > 0.0
    assert result.improvement.net_energy_saved_J == pytest.approx(e00 - e11, abs=1e-6)
    assert d.from_lengths_J is not None and d.from_lengths_J > 0.0
    assert d.from_lengths_J == pytest.approx(e00 - e10, abs=1e-6)
    assert d.from_trajectory_J == pytest.approx(e00 - e01, abs=1e-6)


def test_default_study_results_data_are_current(run: RunOutput, tmp_path: Path) -> None:
    """docs/results/data/xs031_spiral.json (the results pages' numbers) matches this run and its closed loop.

    The run's copy is simulated as the pages' run is (``simulate --payload-error 0.2``) and recorded as
    ``scripts/results_pages.sh`` records it; the data must agree within the tolerances of
    :mod:`hiab_sim.docs_site.results_data`.
    """
    import shutil

    from hiab_sim.cli import main
    from hiab_sim.docs_site.results_data import differences, load_data, record

    folder = tmp_path / "xs031_spiral"
    shutil.copytree(run.folder, folder)
    assert main(["simulate", str(folder), "--payload-error", "0.2", "--no-video", "--no-figures", "--quiet"]) == 0
    assert differences(record(folder), load_data()["xs031_spiral"]) == []


def test_default_run_report_is_self_contained_and_states_the_design(run: RunOutput, result: Result) -> None:
    """hiab-sim report on the default run: one HTML file, nothing external, the design to build and battery energy."""
    from browser_helper import References

    from hiab_sim.design_report import write_report

    (path,) = write_report(run.folder)
    html = path.read_text()
    parser = References()
    parser.feed(html)
    assert parser.tags == [] and all(url.startswith("data:") for url in parser.urls)
    assert result.buildable is not None and result.energy is not None
    lift, tilt = result.buildable.lengths.lift, result.buildable.lengths.tilt
    assert f"lift L / Lc0 / Lc = {lift.L:.3f} / {lift.Lc0:.3f} / {lift.Lc:.3f} m" in html
    assert f"tilt L / Lc0 / Lc = {tilt.L:.3f} / {tilt.Lc0:.3f} / {tilt.Lc:.3f} m" in html
    assert f"{result.energy.optimal.battery_energy_J:.1f} J" in html
    assert result.structure is not None
    most = result.structure.optimal.most_loaded_pin
    peak = result.structure.optimal.pins[most].peak_N
    assert f"Most loaded pin of the optimal design: {most}, {peak / 1e3:.1f} kN peak" in html


def test_the_model_effects_default_row_is_this_run(run: RunOutput) -> None:
    """The effect table's ``hold_brake`` row, made from this run of the default study, is the recorded one.

    The row is built by :func:`~hiab_sim.study.analysis.model_effects.row` from this run's result and
    compared with docs/results/data/xs031_spiral_model_effects.json within the data's tolerances.
    """
    from hiab_sim.docs_site.results_data import differences, load_data
    from hiab_sim.study.analysis.model_effects import LEVELS, row

    committed = load_data().get("xs031_spiral_model_effects")
    if committed is None:
        pytest.fail("no recorded xs031_spiral_model_effects in docs/results/data: run scripts/results_pages.sh")
    level = next(level for level in LEVELS if level.key == "hold_brake")
    recorded = next(r for r in committed["model_effects"]["rows"] if r["key"] == "hold_brake")
    assert differences(row(level, run.result.to_json()), recorded) == []

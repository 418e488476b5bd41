"""The results pages' data are current: re-run each study, record it as the pages do, compare within the tolerances.

The short studies (seconds each) run in CI; the default study and its closed loop are checked in
tests/test_default_study.py on that module's run. The long ones (co-design, duty mix, excavator,
the energy map, the sweeps, the Pareto front and the model-effects table: minutes each) run under
``-m slow``; in CI the long studies' data are held to tests/data/shipped_optima.json instead
(tests/test_results_page.py, and the model-effects table's rows in tests/test_model_effects.py); the
sweeps and the front have no recorded optima, so CI checks only that their pages are what their data
render.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from hiab_sim.docs_site.results_data import differences, load_data, record
from hiab_sim.study.run import run_study

ROOT = Path(__file__).resolve().parents[1]
#: End-to-end runs of whole studies: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e
SHORT_STUDIES = ("xs031_spiral_energy", "xs031_spiral_payload", "xs031_spiral_mounting", "seed_scale_spiral")
LONG_STUDIES = ("xs031_codesign", "xs031_duty_mix", "exact_digging", "exact_grading", "exact_duty_mix")
#: Those over 30 s on 2 cores (with their recorded starts): -m slow, outside CI's budget.
SLOW_LONG_STUDIES = {"xs031_duty_mix", "exact_digging", "exact_duty_mix"}


def _check(study: str, out: Path) -> None:
    """Run ``study`` with as many starts as its recorded run had, record it and compare."""
    committed = load_data()
    if study not in committed:
        pytest.fail(f"no recorded run of {study} in docs/results/data: run scripts/results_pages.sh")
    starts = len(committed[study]["result"]["multistart"]["starts"])
    run_study(ROOT / "optimize" / f"{study}.yaml", out, starts=starts, progress=None, figures=False)
    assert differences(record(out), committed[study]) == []


@pytest.mark.parametrize("study", SHORT_STUDIES)
def test_short_study_data_are_current(study: str, tmp_path: Path) -> None:
    """A fresh run of the study records the committed data within the stated tolerances."""
    _check(study, tmp_path / study)


def _check_command(name: str, args: list[str], out: Path) -> None:
    """Run a hiab-sim command into ``out``, record it and compare with ``docs/results/data/<name>.json``."""
    from hiab_sim.cli import main

    committed = load_data()
    if name not in committed:
        pytest.fail(f"no recorded output of {name} in docs/results/data: run scripts/results_pages.sh")
    assert main([*args, "--out", str(out)]) == 0
    assert differences(record(out), committed[name]) == []


@pytest.mark.e2e
def test_model_effects_data_are_current(tmp_path: Path) -> None:
    """A fresh effect table of the default study (five optimisations, a minute or more) records the committed data."""
    from hiab_sim.study.analysis.model_effects import run_model_effects

    name = "xs031_spiral_model_effects"
    committed = load_data()
    if name not in committed:
        pytest.fail(f"no recorded output of {name} in docs/results/data: run scripts/results_pages.sh")
    run_model_effects(ROOT / "optimize" / "xs031_spiral.yaml", tmp_path / name)
    assert differences(record(tmp_path / name), committed[name]) == []


@pytest.mark.e2e
def test_energy_map_data_are_current(tmp_path: Path) -> None:
    """A fresh energy map of the default study (its start, 50 x 50 cells; minutes on the real drive) is current."""
    _check_command("xs031_spiral_energy_map", ["energy-map", str(ROOT / "optimize" / "xs031_spiral.yaml")], tmp_path)


@pytest.mark.parametrize(
    ("name", "args"),
    [
        ("xs031_mounting_space", ["sweep", "optimize/sweeps/xs031_mounting_space.yaml", "--workers", "2", "--quiet"]),
        pytest.param(
            "xs031_payload_gear",
            ["sweep", "optimize/sweeps/xs031_payload_gear.yaml", "--workers", "2", "--quiet"],
            marks=pytest.mark.slow,
        ),
        pytest.param(
            "xs031_spiral_pareto_peak_force",
            ["pareto", "optimize/xs031_spiral.yaml", "--against", "peak_force"],
            marks=pytest.mark.slow,
        ),
    ],
)
def test_sweep_and_pareto_data_are_current(
    name: str, args: list[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The shipped sweeps and the default Pareto front (tens of optimisations each) record the committed data."""
    monkeypatch.chdir(ROOT)
    _check_command(name, args, tmp_path / name)


@pytest.mark.parametrize(
    "study", [pytest.param(s, marks=pytest.mark.slow) if s in SLOW_LONG_STUDIES else s for s in LONG_STUDIES]
)
def test_long_study_data_are_current(study: str, tmp_path: Path) -> None:
    """A fresh run of a long study (with its recorded number of starts) records the committed data."""
    _check(study, tmp_path / study)

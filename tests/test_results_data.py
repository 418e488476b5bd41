"""The results pages' data are current: re-run each study, record it as the pages do, compare within the tolerances.

The short studies (seconds each) run in CI; the default study and its closed loop are checked in
tests/test_default_study.py on that module's run. The long ones (co-design, duty mix, excavator:
minutes each) run under ``-m slow``; in CI their data are held to tests/data/shipped_optima.json
instead (tests/test_results_page.py).
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
LONG_STUDIES = ("xs031_codesign", "xs031_duty_mix", "exact_digging", "exact_grading")


def _check(study: str, out: Path, starts: int = 1) -> None:
    committed = load_data()
    if study not in committed:
        pytest.fail(f"no recorded run of {study} in docs/results/data: run scripts/results_pages.sh")
    run_study(ROOT / "optimize" / f"{study}.yaml", out, starts=starts, progress=None, figures=False)
    assert differences(record(out), committed[study]) == []


@pytest.mark.parametrize("study", SHORT_STUDIES)
def test_short_study_data_are_current(study: str, tmp_path: Path) -> None:
    """A fresh run of the study records the committed data within the stated tolerances."""
    _check(study, tmp_path / study)


@pytest.mark.slow
@pytest.mark.parametrize("study", LONG_STUDIES)
def test_long_study_data_are_current(study: str, tmp_path: Path) -> None:
    """A fresh run of a long study (the duty mix with its three starts) records the committed data."""
    _check(study, tmp_path / study, starts=3 if study == "xs031_duty_mix" else 1)

"""The validation page's figures: the docs script writes them, and they show the validation table's own measurements."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

from hiab_sim.crane.loader import load_crane
from hiab_sim.docs_site.validation_figures import FIGURES, case_trace
from hiab_sim.validation import DEFAULT_CASES, load_cases, mujoco_path, run_case, with_samples

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.sim
def test_docs_figures_script_writes_the_validation_figures(tmp_path: Path) -> None:
    """`ONLY=validation bash scripts/docs_figures.sh` (4 samples per case) writes both PNGs, each a drawn image."""
    env = {
        **os.environ,
        "ONLY": "validation",
        "FIGURES_DIR": str(tmp_path),
        "VALIDATION_SAMPLES": "4",
        "PYTHON": sys.executable,
    }
    done = subprocess.run(
        ["bash", str(ROOT / "scripts" / "docs_figures.sh")], env=env, capture_output=True, text=True, check=False
    )
    assert done.returncode == 0, done.stderr
    for name in FIGURES:
        image = imread(tmp_path / name)
        assert image.shape[0] > 300 and image.shape[1] > 600, name
        assert np.std(image[..., :3]) > 0.05, name  # not a blank canvas


def test_validation_page_shows_both_figures() -> None:
    """docs/validation.md embeds every figure the script writes, from docs/figures/, and each is committed."""
    page = (ROOT / "docs" / "validation.md").read_text()
    for name in FIGURES:
        assert re.search(rf"\]\(figures/{re.escape(name)}\)", page), name
        assert (ROOT / "docs" / "figures" / name).is_file(), name


@pytest.mark.sim
def test_figure_data_are_the_measurements_the_validation_table_reports() -> None:
    """Per case, the largest plotted force difference and balance residuals equal run_case's maxima."""
    crane = load_crane("xs031")
    tolerances, specs = load_cases(DEFAULT_CASES)
    mujoco = mujoco_path(crane)
    for spec in with_samples(specs, 6):
        trace = case_trace(crane, spec, mujoco)
        result = run_case(crane, spec, mujoco, tolerances)
        assert trace.analytic.shape == (result.samples, 3)
        np.testing.assert_allclose(np.max(trace.force_relative, axis=0), result.force_rel_error, rtol=1e-12, atol=0)
        assert np.max(trace.balance_analytic) == result.balance_analytic, spec.name
        assert np.max(trace.balance_mujoco) == result.balance_mujoco, spec.name
        assert trace.balance_kind == result.balance_kind

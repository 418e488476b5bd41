"""Every study shipped in optimize/ loads, reaches its reference and starts feasible."""

from __future__ import annotations

from pathlib import Path

import pytest

from hiab_sim.study.config import load_study
from hiab_sim.study.problem import LinkLengthProblem
from hiab_sim.study.solve import check_start

STUDIES = sorted((Path(__file__).resolve().parents[1] / "optimize").glob("*spiral*.yaml"))


def test_the_shipped_studies_are_found() -> None:
    """The default, payload and seed-scale studies are all in optimize/."""
    assert {p.name for p in STUDIES} >= {"xs031_spiral.yaml", "xs031_spiral_payload.yaml", "seed_scale_spiral.yaml"}


@pytest.mark.parametrize("path", STUDIES, ids=lambda p: p.stem)
def test_shipped_study_starts_feasible(path: Path) -> None:
    """The study's reference is reachable and its start satisfies every constraint."""
    study = load_study(path)
    problem = LinkLengthProblem(study)
    check_start(problem, problem.initial_point(study.initial_lengths))

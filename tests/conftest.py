"""Shared fixtures, each made once per session: the default crane, the small crane and excavator studies solved."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from hiab_sim.crane.description import Crane
from hiab_sim.crane.loader import load_crane
from hiab_sim.env.machine_plan import MachinePlan, read_machine_plan

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine_result_helper import excavator_move, solved_study
from test_study_small import small_study, write_study

from hiab_sim.cli import main


@pytest.fixture(scope="session")
def crane() -> Crane:
    """The HIAB XS 031 preset."""
    return load_crane("xs031")


@pytest.fixture(scope="session")
def excavator_result(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small excavator study (``machine_result_helper.EXCAVATOR_STUDY``) optimised: its result folder."""
    folder = tmp_path_factory.mktemp("excavator_move")
    excavator_move(folder)
    return solved_study(folder)


@pytest.fixture(scope="session")
def excavator_plan(excavator_result: Path) -> MachinePlan:
    """The optimal design's plan of :func:`excavator_result`."""
    return read_machine_plan(excavator_result, "optimal")


@pytest.fixture(scope="session")
def small_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small crane study (``test_study_small.small_study``) optimised by the CLI (no figures, no video)."""
    folder = tmp_path_factory.mktemp("small_run")
    study = write_study(folder, small_study())
    assert main(["optimize", str(study), "--out", str(folder / "out"), "--no-video", "--quiet", "--no-figures"]) == 0
    return folder / "out"

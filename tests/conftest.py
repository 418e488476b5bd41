"""Shared fixtures, each made once per session: the default crane, the small crane and excavator studies solved.

The solved studies import what runs them inside their fixtures, so collecting the tests imports no MuJoCo
(``hiab_sim.cli.main`` picks the OpenGL backend before MuJoCo's first import).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from hiab_sim.crane.description import Crane
from hiab_sim.crane.loader import load_crane

if TYPE_CHECKING:
    from hiab_sim.env.machine_plan import MachinePlan

sys.path.insert(0, str(Path(__file__).resolve().parent))


@pytest.fixture(scope="session")
def crane() -> Crane:
    """The HIAB XS 031 preset."""
    return load_crane("xs031")


@pytest.fixture(scope="session")
def excavator_result(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small excavator study (``machine_result_helper.EXCAVATOR_STUDY``) optimised: its result folder."""
    from machine_result_helper import excavator_move, solved_study

    folder = tmp_path_factory.mktemp("excavator_move")
    excavator_move(folder)
    return solved_study(folder)


@pytest.fixture(scope="session")
def excavator_plan(excavator_result: Path) -> MachinePlan:
    """The optimal design's plan of :func:`excavator_result`."""
    from hiab_sim.env.machine_plan import read_machine_plan

    return read_machine_plan(excavator_result, "optimal")


@pytest.fixture(scope="session")
def small_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small crane study (``test_study_small.small_study``) optimised by the CLI (no figures, no video)."""
    from test_study_small import small_study, write_study

    from hiab_sim.cli import main

    folder = tmp_path_factory.mktemp("small_run")
    study = write_study(folder, small_study())
    assert main(["optimize", str(study), "--out", str(folder / "out"), "--no-video", "--quiet", "--no-figures"]) == 0
    return folder / "out"

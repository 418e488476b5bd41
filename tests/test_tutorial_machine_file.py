"""The own-machine tutorial's machine file written from scratch, as the page shows it: it checks and its study loads.

The fast half of ``test_tutorials.test_own_machine_from_scratch_checks_draws_and_optimises`` (end to end, which
also draws and optimises it): the page's titled blocks are written and its python block run, nothing else.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from test_tutorials import SCRATCH_SECTION, TUTORIALS, run_blocks, section_blocks

from hiab_sim.cli import main


def test_tutorial_machine_file_checks_and_its_study_starts_as_the_page_says(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The tutorial's machine file passes ``machine check`` with the line the page quotes, and its study starts.

    The study loads with the page's decision variables and a task as long as the CSV (6 s = grid.duration, so
    12 intervals and 10 control points), and its start keeps the inverse dynamics' 0.02 rad margin.
    """
    from hiab_sim.study.nlp.task_problem import TaskProblem
    from hiab_sim.study.spec.study_file import load_study

    run_blocks("own-machine.md", section_blocks(TUTORIALS / "own-machine.md", *SCRATCH_SECTION), tmp_path, ("python",))
    assert main(["machine", "check", str(tmp_path / "my_loader.yaml")]) == 0
    assert "every chain assembles over its working range (2 chains)" in capsys.readouterr().out
    study = load_study(tmp_path / "my_lift.yaml")
    assert tuple(study.model.design_names) == ("lift.L", "lift.Lc0", "lift.Lc")
    assert study.tasks[0].reference.duration == pytest.approx(study.grid.duration)
    problem = TaskProblem(study)  # refuses a start within 0.02 rad of a triangle joint's range end
    assert len(problem.collocation_times) == 13 and problem.basis.n == 10

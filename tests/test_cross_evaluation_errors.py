"""Cross-evaluation says why a cell is empty, and a missing IPOPT backend is an error, not an empty cell."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import pytest
from test_mix import two_tasks

from hiab_sim.errors import BackendUnavailableError
from hiab_sim.study.analysis.cross_evaluation import cross_evaluation
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.spec.study_file import study_from_dict


@pytest.fixture(scope="module")
def mix() -> StudyProblem:
    return StudyProblem(study_from_dict(two_tasks(), "two.yaml"))


def test_without_casadi_cross_evaluation_raises_backend_unavailable_naming_the_extra(
    mix: StudyProblem, monkeypatch: pytest.MonkeyPatch
) -> None:
    """No CasADi: BackendUnavailableError naming ``pip install 'hiab-sim[ipopt]'``, not empty cells."""
    monkeypatch.setitem(sys.modules, "casadi", None)  # import casadi raises ImportError
    start = mix.study.initial_lengths
    z = mix.initial_point(start)
    with pytest.raises(BackendUnavailableError, match=r"hiab-sim\[ipopt\]"):
        cross_evaluation(mix, z, alone=[start, start])


def test_a_design_outside_the_model_domain_gets_empty_cells_that_say_why(mix: StudyProblem) -> None:
    """A design whose lift chain cannot close: every cell on its row is None with the model's reason."""
    pytest.importorskip("casadi")
    start = mix.study.initial_lengths
    broken = replace(start, lift=replace(start.lift, L=0.05))  # base pivot 5 cm from the hinge: no triangle
    z = mix.initial_point(start)
    cross = cross_evaluation(mix, z, alone=[broken, start])
    assert cross.net_energy_J[0] == (None, None)
    assert all(reason.startswith("cannot be evaluated:") for reason in cross.unserved[0])
    assert all("lift" in reason for reason in cross.unserved[0])
    # The built crane serves both tasks: its cells hold numbers and no reason.
    assert all(v is not None for v in cross.net_energy_J[1]) and cross.unserved[1] == ("", "")


def test_without_distributed_a_dask_sweep_raises_backend_unavailable_naming_the_extra(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--dask`` without dask.distributed: BackendUnavailableError naming ``pip install 'hiab-sim[dask]'``."""
    from hiab_sim.sweep.executors import make_executor

    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(BackendUnavailableError, match=r"hiab-sim\[dask\]"), make_executor(dask="tcp://127.0.0.1:1"):
        pass


def test_without_casadi_an_ipopt_study_exits_2_naming_the_extra(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``hiab-sim optimize`` of an IPOPT study without CasADi: exit 2, one line naming the extra, no result."""
    import yaml
    from test_study_small import small_study

    from hiab_sim.cli import main

    monkeypatch.setitem(sys.modules, "casadi", None)
    data = small_study()
    data["solver"] = {**data["solver"], "method": "ipopt"}
    path = tmp_path / "ipopt.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    assert main(["optimize", str(path), "--out", str(out), "--quiet", "--no-video"]) == 2
    err = capsys.readouterr().err
    assert "hiab-sim[ipopt]" in err and len(err.strip().splitlines()) == 1
    assert not (out / "result.json").exists()


def test_the_best_of_two_starts_answers_when_one_start_fails_and_raises_when_both_do(
    mix: StudyProblem, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A start whose solve raises leaves the other to answer; when every start raises, the first error is raised."""
    import numpy as np

    from hiab_sim.errors import InvalidInputError, SolverError
    from hiab_sim.study.analysis import cross_evaluation as module

    task = mix.problems[0]
    start = mix.study.initial_lengths
    fitted = task.initial_point(start)

    def fake(problem: object, lengths: object, coefficients: object) -> tuple[np.ndarray, bool, str]:
        if coefficients is None:
            raise SolverError("the fit's start failed")
        return fitted, True, "from its own trajectory"

    monkeypatch.setattr(module, "fixed_lengths_optimum", fake)
    z, message = module.best_fixed_lengths_optimum(mix, task, start, [None, np.zeros(3)])
    assert message == "from its own trajectory" and np.array_equal(z, fitted)

    def failing(problem: object, lengths: object, coefficients: object) -> tuple[np.ndarray, bool, str]:
        raise (InvalidInputError("lift.L", 0.05, "no triangle") if coefficients is None else SolverError("second"))

    monkeypatch.setattr(module, "fixed_lengths_optimum", failing)
    with pytest.raises(InvalidInputError, match=r"lift\.L"):
        module.best_fixed_lengths_optimum(mix, task, start, [None, np.zeros(3)])

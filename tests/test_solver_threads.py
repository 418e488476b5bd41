"""Both solvers run numpy's and scipy's BLAS on one thread while they solve, and give the pool back after.

The limit is observed from inside the solve (each solver's per-iterate hook reads threadpoolctl's view
of the loaded BLAS libraries), so a solver that lost its limit fails here, whatever the machine's
core count (a 1-core machine has nothing to limit: the test then checks only the restore).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from test_study_small import small_study
from threadpoolctl import threadpool_info

from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers.slsqp import solve
from hiab_sim.study.spec.study_file import study_from_dict


def _blas_threads() -> dict[str, int]:
    """The thread count of every loaded BLAS library (numpy's, scipy's, CasADi's once loaded), by its file."""
    return {info["filepath"]: int(info["num_threads"]) for info in threadpool_info() if info["user_api"] == "blas"}


def _problem() -> tuple[StudyProblem, Any]:
    study = study_from_dict(small_study(), "small.yaml")
    return StudyProblem(study), study.initial_lengths


def test_slsqp_iterates_with_one_blas_thread_and_restores_the_pool() -> None:
    """Every SLSQP iterate is recorded with one BLAS thread; afterwards the pool is what it was."""
    before = _blas_threads()
    seen: list[dict[str, int]] = []
    problem, initial = _problem()
    result = solve(problem, initial, progress=None, on_iterate=lambda _: seen.append(_blas_threads()))
    assert result.success and len(seen) > 2
    assert all(counts and set(counts.values()) == {1} for counts in seen[1:])  # seen[0]: the start, before
    assert _blas_threads() == before


def test_ipopt_iterates_with_one_blas_thread_and_restores_the_pool() -> None:
    """Every IPOPT iterate sees one thread in every BLAS, CasADi's under MUMPS included; the pools are restored."""
    pytest.importorskip("casadi")
    from hiab_sim.study.solvers.ipopt import solve_ipopt

    problem, initial = _problem()
    seen: list[dict[str, int]] = []
    z0 = problem.initial_point(initial)
    solve_ipopt(problem, np.asarray(z0), 1, 1e-7)  # loads CasADi and its OpenBLAS
    before = _blas_threads()
    assert any("casadi" in path for path in before), before  # threadpoolctl finds CasADi's OpenBLAS
    outcome = solve_ipopt(problem, np.asarray(z0), 3, 1e-7, on_iterate=lambda _: seen.append(_blas_threads()))
    assert outcome.iterations >= 1 and seen
    assert all(counts == dict.fromkeys(before, 1) for counts in seen)
    assert _blas_threads() == before

"""Benchmark: a solve with numpy's and scipy's BLAS on one thread (the solvers' setting) vs the default pool.

:mod:`hiab_sim.study.solvers.threads` limits BLAS to one thread while SLSQP or IPOPT runs. The
baseline here is the same solve with that limit replaced by a no-op (the pool of one thread per
core), alternating in one process: the default study to its optimum and the first ``--iterations``
SLSQP iterations of the eXact digging study. ``--busy N`` starts N busy-looping processes beside the
solves (a test run's workers, a sweep), stopped when the benchmark ends. Only the ratios of one run
mean anything on a shared machine.

Run: .venv/bin/python benchmarks/bench_solver_threads.py [--repeat 2] [--iterations 12] [--busy 2]
"""

from __future__ import annotations

import argparse
import contextlib
import multiprocessing
import time
from collections.abc import Iterator

from hiab_sim.errors import SolverError
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers import slsqp
from hiab_sim.study.spec.study_file import load_study


def _spin() -> None:
    while True:
        pass


@contextlib.contextmanager
def _busy(n: int) -> Iterator[None]:
    """N processes looping on a core each, stopped on exit."""
    procs = [multiprocessing.Process(target=_spin, daemon=True) for _ in range(n)]
    for p in procs:
        p.start()
    try:
        yield
    finally:
        for p in procs:
            p.terminate()
            p.join()


def _solve(name: str, maxiter: int | None, pooled: bool) -> tuple[float, int]:
    """Wall time [s] and iterations of one SLSQP solve (problem built outside the clock)."""
    study = load_study(name)
    problem = StudyProblem(study)
    limit = slsqp.single_blas_thread
    if pooled:
        slsqp.single_blas_thread = contextlib.nullcontext
    try:
        t0 = time.perf_counter()
        try:
            iterations = slsqp.solve(problem, study.initial_lengths, progress=None, maxiter=maxiter).iterations
        except SolverError:  # the iteration limit of a partial solve
            iterations = maxiter or 0
        return time.perf_counter() - t0, iterations
    finally:
        slsqp.single_blas_thread = limit


def main() -> None:
    """Print each solve's wall time with one BLAS thread and with the pool, and their ratio."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--iterations", type=int, default=12, help="SLSQP iterations of the digging study")
    parser.add_argument("--busy", type=int, default=0, help="busy processes beside the solves")
    args = parser.parse_args()
    cases = (("xs031_spiral", None), ("exact_digging", args.iterations))
    with _busy(args.busy):
        for name, maxiter in cases:
            walls: dict[bool, list[float]] = {True: [], False: []}
            for _ in range(args.repeat):
                for pooled in (True, False):
                    wall, iterations = _solve(name, maxiter, pooled)
                    walls[pooled].append(wall)
                    label = "default pool" if pooled else "one thread"
                    print(f"{name:14s} {label:12s} wall {wall:7.2f} s  iterations {iterations}", flush=True)
            best = {k: min(v) for k, v in walls.items()}
            print(
                f"{name}: pool / one thread = {best[True] / best[False]:.2f} (best of {args.repeat}, busy {args.busy})"
            )


if __name__ == "__main__":
    main()

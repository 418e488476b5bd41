"""Benchmark: the duty-mix study (single start) against the default single-task study in the same run.

Solves from the built XS 031's lengths, each ``--repeat`` times (fresh problem each time; the
minimum and the median wall time are printed): the default study (``xs031_spiral``, dense SLSQP,
its result unchanged by the tasks loader), the duty mix with its own solver (IPOPT, sparse
Jacobians) and, with ``--slsqp N``, the duty mix with dense SLSQP for at most N iterations (its
seconds per iteration are the measure of whether dense SLSQP serves the mix). Goals:
the duty mix <= 10 s wall on 2 cores and <= 100 iterations; the default study no slower than
before (~0.6-1 s). Wall times depend on the machine's load: compare them with the default
study's in the same run.

Run: .venv/bin/python benchmarks/bench_duty_mix.py [--repeat 3] [--slsqp 10]
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import replace

import numpy as np

from hiab_sim.errors import SolverError
from hiab_sim.study.nlp.problem import make_problem
from hiab_sim.study.solvers.slsqp import solve
from hiab_sim.study.spec.study_file import DEFAULT_STUDY, Study, load_study


def _run(study: Study, maxiter: int | None = None) -> dict[str, object]:
    t0 = time.perf_counter()
    problem = make_problem(study)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    try:
        result = solve(problem, study.initial_lengths, progress=None, maxiter=maxiter)
        message, z, iterations = result.message, result.z, result.iterations
    except SolverError as error:  # e.g. the iteration limit of the dense SLSQP probe
        message, z, iterations = str(error), None, maxiter or -1
    wall = time.perf_counter() - t0
    out: dict[str, object] = {"build": build, "wall": wall, "iterations": iterations, "message": message}
    out["variables"], out["rows"] = problem.n, len(problem.constraint_names)
    if z is not None:
        out["cost"] = problem.cost(z)
        out["violation"] = problem.max_violation(z)
        out["xi"] = np.round(problem.unpack(z)[0].as_array(), 4).tolist()
    return out


def _repeated(study: Study, repeat: int, maxiter: int | None = None) -> dict[str, object]:
    """:func:`_run` ``repeat`` times: the last run's numbers with the minimum and median wall time."""
    runs = [_run(study, maxiter) for _ in range(repeat)]
    walls = [float(r["wall"]) for r in runs]  # type: ignore[arg-type]
    return {**runs[-1], "wall": min(walls), "median": statistics.median(walls)}


def main() -> None:
    """Run the solves and print wall time (min, median), iterations, size, cost and Xi of each."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="solves per study (min and median wall time)")
    parser.add_argument("--slsqp", type=int, default=0, help="also run dense SLSQP on the mix for N iterations")
    args = parser.parse_args()
    mix = load_study("xs031_duty_mix")
    runs = {
        "default study (SLSQP)": _repeated(load_study(str(DEFAULT_STUDY)), args.repeat),
        f"duty mix ({mix.solver.method.upper()})": _repeated(mix, args.repeat),
    }
    if args.slsqp:
        dense = replace(mix, solver=replace(mix.solver, method="slsqp"))
        runs[f"duty mix (SLSQP, {args.slsqp} it.)"] = _repeated(dense, 1, maxiter=args.slsqp)
    for name, r in runs.items():
        per = float(r["wall"]) / max(1, int(r["iterations"]))  # type: ignore[call-overload]
        print(
            f"{name:28s} n {r['variables']:4d} rows {r['rows']:5d}  build {r['build']:5.2f} s"
            f"  wall {r['wall']:6.2f} s (median {r['median']:6.2f} s)  iterations {r['iterations']:4d}"
            f" ({per:.3f} s/it.)  cost {r.get('cost', float('nan')):.7f}"
            f"  violation {r.get('violation', float('nan')):.1e}  Xi {r.get('xi')}  [{r['message']}]"
        )


if __name__ == "__main__":
    main()

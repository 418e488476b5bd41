"""Sweep throughput: the same 40-point sweep on 1 and 2 local worker processes and on a 2-worker Dask cluster.

Usage: ``.venv/bin/python benchmarks/bench_sweep.py [--points 40]``. The sweep is a payload grid over a
small study (16 control points, 9 collocation points, analytic ID; a few seconds per optimisation). Every
executor runs the whole sweep into a fresh folder; the wall time includes starting the local worker
processes (not the Dask cluster, which a user's cluster already runs). Also reported: the round trip of
a trivial task on each executor (the per-point overhead of the execution engine itself).
Goal: 2 local workers >= 1.7x faster than 1.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from concurrent.futures import Executor
from pathlib import Path

import numpy as np
import yaml

from hiab_sim.sweep.executors import make_executor
from hiab_sim.sweep.runner import run_sweep
from hiab_sim.sweep.spec import load_sweep

# The benchmark reuses the tests' shared small study (tests/ is a folder of modules, not a package).
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_study_small import TINY, small_study

#: The tests' small study on their tiny grid (a few seconds per optimisation).
STUDY = small_study(name="bench", **TINY)


def trivial(k: int) -> int:
    return k


def round_trip(executor: Executor, n: int = 200) -> float:
    """Seconds per trivial task submitted and gathered."""
    list(executor.map(trivial, range(10)))  # warm up
    t0 = time.perf_counter()
    futures = [executor.submit(trivial, k) for k in range(n)]
    for f in futures:
        f.result()
    return (time.perf_counter() - t0) / n


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=40)
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    (folder / "study.yaml").write_text(yaml.safe_dump(STUDY))
    payloads = [float(p) for p in np.linspace(0.0, 300.0, args.points)]
    (folder / "sweep.yaml").write_text(yaml.safe_dump({"study": "study.yaml", "grid": {"payload": payloads}}))
    sweep = load_sweep(folder / "sweep.yaml")
    wall: dict[str, float] = {}
    per_point: dict[str, float] = {}
    for workers in (1, 2):
        t0 = time.perf_counter()
        with make_executor(workers=workers) as executor:
            outcome = run_sweep(sweep, folder / f"local{workers}", executor, progress=False)
        wall[f"local {workers}"] = time.perf_counter() - t0
        print(f"{workers} local worker(s): {wall[f'local {workers}']:.1f} s, {len(outcome.failed)} failed", flush=True)
    with make_executor(workers=2) as executor:
        per_point["local"] = round_trip(executor)
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with make_executor(dask=cluster.scheduler_address) as executor:
            per_point["dask"] = round_trip(executor)
        t0 = time.perf_counter()
        with make_executor(dask=cluster.scheduler_address) as executor:
            outcome = run_sweep(sweep, folder / "dask", executor, progress=False)
        wall["dask 2"] = time.perf_counter() - t0
    n = args.points
    print(f"{n}-point sweep of a small study (payload 0..300 kg)")
    for key, value in wall.items():
        print(f"  {key:8s}: {value:7.1f} s wall, {value / n:.2f} s/point")
    print(f"speed-up 2 vs 1 local workers: {wall['local 1'] / wall['local 2']:.2f}x (goal >= 1.7x)")
    print(f"Dask vs local (2 workers each): {(wall['dask 2'] - wall['local 2']) / n * 1e3:+.0f} ms/point")
    print(
        f"trivial-task round trip: local processes {per_point['local'] * 1e3:.2f} ms, "
        f"Dask {per_point['dask'] * 1e3:.2f} ms per task"
    )


if __name__ == "__main__":
    main()

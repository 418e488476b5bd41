"""Energy map of the default study: a 50 x 50 grid, stacked designs vs a per-design loop, same run.

Usage: ``.venv/bin/python benchmarks/bench_energy_map.py [--grid 50] [--repeats 3] [--loop 100]``.
Times the whole map (the problem is built once, outside the timing, as the CLI does before the map)
and, as the baseline, the per-design path (:meth:`TaskProblem.evaluate` on the collocation grid
plus the fine-grid power) over ``--loop`` admissible designs, scaled to the grid's cell count.
Goal: the 50 x 50 map in <= 2 s wall on 2 cores.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hiab_sim.crane.description import LinkLengths
from hiab_sim.errors import HiabSimError
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.report.design_check import fine_problem
from hiab_sim.study.spec.study_file import load_study
from hiab_sim.sweep.energy_map import energy_map, start_design


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, default=50)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--loop", type=int, default=100)
    args = parser.parse_args()
    study = load_study(None)
    problem = TaskProblem(study, id_path="analytic")
    fine = fine_problem(problem, "analytic")
    base = start_design(problem)
    times = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        m = energy_map(problem, base, (0, 1), args.grid)
        times.append(time.perf_counter() - t0)
    t_map = min(times)
    cells = args.grid**2
    # baseline: one design at a time through the NLP's own evaluation (admissible designs only)
    z0 = problem.initial_point(study.initial_lengths)
    xi = m.values.xi[m.values.feasible][: args.loop]
    t0 = time.perf_counter()
    done = 0
    for x in xi:
        z = z0.copy()
        z[:6] = x
        try:
            problem.evaluate(z)
            fine.evaluate(np.concatenate([LinkLengths.from_array(x).as_array(), z0[6:]]))
            done += 1
        except HiabSimError:
            continue
    t_loop = (time.perf_counter() - t0) / max(done, 1) * cells
    print(f"{args.grid} x {args.grid} energy map of {study.name} (lift.L x lift.Lc0, start), best of {args.repeats}")
    print(f"stacked designs: {t_map:.3f} s wall ({t_map / cells * 1e6:.0f} us/cell; goal <= 2 s)")
    print(f"per-design loop: {t_loop:.1f} s for {cells} cells (from {done} designs); ratio {t_loop / t_map:.0f}x")
    print(f"feasible cells: {int(m.values.feasible.sum())} of {cells}")


if __name__ == "__main__":
    main()

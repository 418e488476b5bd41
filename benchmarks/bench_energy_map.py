"""Energy map of a study: time per cell of the map, refused and evaluated cells counted apart.

Usage: ``.venv/bin/python benchmarks/bench_energy_map.py [STUDY] [--grid 20] [--vars lift.L,lift.Lc0]``.
The map evaluates every cell through the study's own NLP (:mod:`hiab_sim.sweep.map_values`: the
collocation grid's objective and rows, the fine grid's energies); a cell the inverse dynamics
refuses costs only its rows of Xi alone. The problem and the base design are built outside the
timing, as the CLI does before the map. With a duty model most of an evaluated cell's time is the
hot-winding solve of each drive on the fine grid (:func:`hiab_sim.emla.duty_energy.drive_duty`).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.spec.study_file import load_study
from hiab_sim.sweep.energy_map import energy_map, parse_variables, start_design


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", nargs="?", default=None)
    parser.add_argument("--grid", type=int, default=20)
    parser.add_argument("--vars", default=None)
    args = parser.parse_args()
    study = load_study(args.study)
    problem = StudyProblem(study, id_path="analytic")
    variables = parse_variables(args.vars, tuple(problem.model.design_names))
    base = start_design(problem)
    t0 = time.perf_counter()
    m = energy_map(problem, base, variables, args.grid)
    wall = time.perf_counter() - t0
    cells = args.grid**2
    evaluated = int(np.isfinite(m.values.objective).sum())
    print(f"{args.grid} x {args.grid} energy map of {study.name} ({' x '.join(m.variables)}, start), "
          f"{problem.n_tasks} task(s)")  # fmt: skip
    print(f"{wall:.2f} s wall, {wall / cells * 1e3:.1f} ms/cell; {evaluated} cells evaluated, "
          f"{cells - evaluated} refused by the inverse dynamics; {int(m.values.feasible.sum())} feasible")  # fmt: skip


if __name__ == "__main__":
    main()

"""Benchmark: the default study on the crane file vs the same study on the XS 031 machine file; the digging study.

The machine file's study runs the generic path (tracked kinematics, loop closure, Newton-Euler with a
batch over the perturbed designs); the crane file's the closed-form crane path. Both are solved from
the same start in one process, alternating, best of ``--repeat``; only their ratio means anything on
a shared machine. Then the eXact digging study from one start (its wall time, iterations, energies).
Goals (the any-machine issue): the ratio <= 1 (the default study no slower than on the crane file);
the digging study under 5 s on 2 cores from one start.

With ``--ipopt`` the digging study is solved again with IPOPT (sparse Jacobians, L-BFGS), the
shipped XS 031 duty mix's solver; the shipped digging study stays on SLSQP (docs/results/excavator.md).

Run: .venv/bin/python benchmarks/bench_machine_study.py [--repeat 3] [--no-digging] [--ipopt]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers.slsqp import solve
from hiab_sim.study.spec.study_file import load_study

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from test_machine_study import _machine_form  # noqa: E402  (the one text transformation the test uses)


def _solve(path: Path | str) -> tuple[float, int, float]:
    """Wall time [s] of one SLSQP solve (problem built outside the clock), iterations, scaled cost."""
    study = load_study(path)
    problem = StudyProblem(study)
    t0 = time.perf_counter()
    result = solve(problem, study.initial_lengths, progress=None)
    wall = time.perf_counter() - t0
    return wall, result.iterations, problem.cost(result.z)


def _solve_ipopt(path: Path | str) -> tuple[float, int, float, str, float]:
    """Wall time [s] of one IPOPT solve of the study's problem (built outside the clock), its outcome."""
    from hiab_sim.study.solvers.ipopt import solve_ipopt

    study = load_study(path)
    problem = StudyProblem(study)
    z0 = problem.initial_point(study.initial_lengths)
    t0 = time.perf_counter()
    out = solve_ipopt(problem, z0, maxiter=300, tol=1e-7)
    wall = time.perf_counter() - t0
    return wall, out.iterations, problem.cost(out.z), out.message, problem.max_violation(out.z)


def main() -> None:
    """Print both default-study walls and their ratio, then the digging study's."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-digging", action="store_true")
    parser.add_argument("--ipopt", action="store_true", help="also solve the digging study with IPOPT (needs CasADi)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        machine = Path(folder) / "xs031_spiral_machine.yaml"
        machine.write_text(_machine_form((ROOT / "optimize" / "xs031_spiral.yaml").read_text()))
        walls: dict[str, list[float]] = {"crane file": [], "machine file": []}
        for _ in range(args.repeat):
            for name, path in (("crane file", ROOT / "optimize" / "xs031_spiral.yaml"), ("machine file", machine)):
                wall, iterations, cost = _solve(path)
                walls[name].append(wall)
                print(f"{name:13s} wall {wall:6.2f} s  iterations {iterations}  scaled cost {cost:.9f}")
        best = {k: min(v) for k, v in walls.items()}
        print(f"machine file / crane file: {best['machine file'] / best['crane file']:.2f} (best of {args.repeat})")
    if not args.no_digging:
        wall, iterations, cost = _solve("exact_digging")
        print(f"exact_digging: wall {wall:.1f} s, {iterations} iterations, scaled cost {cost:.6f} (one start)")
        if args.ipopt:
            wall, iterations, cost, message, violation = _solve_ipopt("exact_digging")
            print(
                f"exact_digging on IPOPT (ftol 1e-7): wall {wall:.1f} s, {iterations} iterations, {message}, "
                f"scaled cost {cost:.6f}, largest violation {violation:.1e} (one start)"
            )


if __name__ == "__main__":
    main()

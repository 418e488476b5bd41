"""Benchmark: the default study on the crane file vs the same study on the XS 031 machine file; the digging study.

The machine file's study runs the generic path (tracked kinematics, loop closure, Newton-Euler with a
batch over the perturbed designs); the crane file's the closed-form crane path. Both are solved from
the same start in one process, alternating, best of ``--repeat``; only their ratio means anything on
a shared machine. Then the eXact digging study from one start with its own solver (IPOPT, an 80-pair
L-BFGS Hessian: its wall time, iterations, cost). Goals (the any-machine issue): the ratio <= 1 (the
default study no slower than on the crane file); the digging study under 5 s on 2 cores from one start.

With ``--slsqp`` the digging study is solved again with dense SLSQP (the baseline its study used
before; minutes), and with ``--history N ...`` with IPOPT keeping N L-BFGS pairs (IPOPT's default: 6).

Run: .venv/bin/python benchmarks/bench_machine_study.py [--repeat 3] [--no-digging] [--slsqp] [--history 6 50]
"""

from __future__ import annotations

import argparse
import dataclasses
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


def _solve(path: Path | str, **solver: object) -> tuple[float, int, float, float]:
    """Wall time [s] of one solve (problem built outside the clock), iterations, scaled cost, largest violation.

    ``solver``: settings that replace the study's (``method``, ``lbfgs_history``).
    """
    study = load_study(path)
    if solver:
        study = dataclasses.replace(study, solver=dataclasses.replace(study.solver, **solver))
    problem = StudyProblem(study)
    t0 = time.perf_counter()
    result = solve(problem, study.initial_lengths, progress=None)
    wall = time.perf_counter() - t0
    return wall, result.iterations, problem.cost(result.z), problem.max_violation(result.z)


def main() -> None:
    """Print both default-study walls and their ratio, then the digging study's."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-digging", action="store_true")
    parser.add_argument("--slsqp", action="store_true", help="also solve the digging study with dense SLSQP (minutes)")
    parser.add_argument("--history", type=int, nargs="*", default=[], help="also with IPOPT keeping these L-BFGS pairs")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        machine = Path(folder) / "xs031_spiral_machine.yaml"
        machine.write_text(_machine_form((ROOT / "optimize" / "xs031_spiral.yaml").read_text()))
        walls: dict[str, list[float]] = {"crane file": [], "machine file": []}
        for _ in range(args.repeat):
            for name, path in (("crane file", ROOT / "optimize" / "xs031_spiral.yaml"), ("machine file", machine)):
                wall, iterations, cost, _ = _solve(path)
                walls[name].append(wall)
                print(f"{name:13s} wall {wall:6.2f} s  iterations {iterations}  scaled cost {cost:.9f}")
        best = {k: min(v) for k, v in walls.items()}
        print(f"machine file / crane file: {best['machine file'] / best['crane file']:.2f} (best of {args.repeat})")
    if args.no_digging:
        return
    runs: list[tuple[str, dict[str, object]]] = [("its study's solver", {})]
    runs += [(f"IPOPT, {h} L-BFGS pairs", {"method": "ipopt", "lbfgs_history": h}) for h in args.history]
    runs += [("dense SLSQP", {"method": "slsqp"})] if args.slsqp else []
    for label, solver in runs:
        wall, iterations, cost, violation = _solve("exact_digging", **solver)
        print(
            f"exact_digging, {label}: wall {wall:.1f} s, {iterations} iterations, scaled cost {cost:.9f}, "
            f"largest violation {violation:.1e} (one start)"
        )


if __name__ == "__main__":
    main()

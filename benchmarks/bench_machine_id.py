"""Generic machine inverse dynamics (Newton-Euler) vs the crane's analytic path on the XS 031, same run.

Usage: ``.venv/bin/python benchmarks/bench_machine_id.py [--repeats 40] [--rounds 5]``.

The machine path runs on ``presets/xs031_machine.yaml``, the crane path on ``presets/hiab_xs031.yaml``
(the same crane: tests/test_machine_dynamics.py holds the forces equal to 1e-12). Timed, as the
optimiser calls them:

- one ID call on T = 26, 468 (18 x 26, the joint partials of 26 samples) and 4680 (18 x 260)
  random states with a 250 kg payload (``AnalyticInverseDynamics`` vs ``NewtonEulerInverseDynamics``);
- building the ID object for a new design (the crane's length check is not cached: every design
  is new, as in an optimisation);
- the 12 perturbed designs of a finite-difference gradient on 26 samples in one call
  (``batched_inverse_dynamics`` of each path).

Each case first times the crane path alone (``repeats`` calls, before the machine path of that
case has run: numpy's temporaries are cheapest on a heap no other code has shaped yet), then both
paths in alternation (``rounds`` times ``repeats`` calls each), so that load from other processes
hits both alike; the best wall-clock time of each path is kept.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
from timing_helper import best_wall

from hiab_sim.crane.description import LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics as crane_batch
from hiab_sim.dynamics.analytic_id import AnalyticInverseDynamics
from hiab_sim.dynamics.analytic_planar import planar_model
from hiab_sim.machine.dynamics.newton_euler import NewtonEulerInverseDynamics
from hiab_sim.machine.dynamics.newton_euler import batched_inverse_dynamics as machine_batch
from hiab_sim.machine.loader import load_machine
from hiab_sim.validation import random_states

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from lengths_helper import feasible_lengths

PAYLOAD = np.array([0.0, -250.0 * 9.81, 0.0])  # N, 250 kg at the TCP


def alternate(
    rounds: int, repeats: int, crane: Callable[[], object], machine: Callable[[], object]
) -> tuple[float, float]:
    """Best wall-clock seconds of each function: the crane's alone first, then both in alternation."""
    best_crane, best_machine = best_wall(repeats, crane), float("inf")
    for _ in range(rounds):
        best_crane = min(best_crane, best_wall(repeats, crane))
        best_machine = min(best_machine, best_wall(repeats, machine))
    return best_crane, best_machine


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    crane, machine = load_crane("xs031"), load_machine("xs031")
    lengths = crane.default_lengths
    analytic, generic = AnalyticInverseDynamics(crane, lengths), NewtonEulerInverseDynamics(machine)
    rows = []
    for samples in (26, 468, 4680):
        joints = random_states(crane, np.random.default_rng(samples), samples)
        q, dq, ddq = joints.position, joints.velocity, joints.acceleration
        times = alternate(
            args.rounds,
            args.repeats,
            lambda j=joints: analytic(j, tcp_force=PAYLOAD),
            lambda q=q, dq=dq, ddq=ddq: generic(q, dq, ddq, PAYLOAD[:2]),
        )
        a, g = analytic(joints, tcp_force=PAYLOAD).force, generic(q, dq, ddq, PAYLOAD[:2]).force
        error = float(np.max(np.abs(g - a)) / np.max(np.abs(a)))
        rows.append((f"ID call, T = {samples}", *times, error))

    rng = np.random.default_rng(1)
    bounds = [(v.low, v.high) for v in machine.decision_variables]
    designs = [x for x in (feasible_lengths(u).as_array() for u in rng.uniform(0.2, 0.8, (200, 6)))]
    designs = [x for x in designs if all(lo <= v <= hi for v, (lo, hi) in zip(x, bounds, strict=True))]
    counter = iter(range(10**9))

    def build_crane() -> object:
        planar_model.cache_clear()  # a new design: its lengths are checked once
        return AnalyticInverseDynamics(crane, LinkLengths.from_array(designs[next(counter) % len(designs)]))

    def build_machine() -> object:
        return NewtonEulerInverseDynamics(machine, designs[next(counter) % len(designs)])

    rows.append(("build for a new design", *alternate(args.rounds, args.repeats, build_crane, build_machine), 0.0))

    joints = random_states(crane, np.random.default_rng(26), 26)
    q, dq, ddq = joints.position, joints.velocity, joints.acceleration
    xi = lengths.as_array()
    h = 1e-6 * np.maximum(1.0, np.abs(xi))
    stencil = np.repeat(xi[None], 12, axis=0)
    stencil[0::2] += np.diag(h)
    stencil[1::2] -= np.diag(h)
    times = alternate(
        args.rounds,
        args.repeats,
        lambda: crane_batch(crane, stencil, q, dq, ddq, PAYLOAD),
        lambda: machine_batch(machine, stencil, q, dq, ddq, PAYLOAD[:2]),
    )
    a = crane_batch(crane, stencil, q, dq, ddq, PAYLOAD)[0]
    g = machine_batch(machine, stencil, q, dq, ddq, PAYLOAD[:2])[0]
    error = float(np.max(np.abs(g - a)) / np.max(np.abs(a)))
    rows.append(("12 designs x 26 samples, one call", *times, error))

    print(f"XS 031, best of {args.rounds} x {args.repeats} alternating calls; crane = hiab_xs031.yaml analytic path")
    print(f"{'':36s} {'crane [ms]':>11s} {'machine [ms]':>13s} {'machine/crane':>14s} {'max rel. diff':>14s}")
    for label, t_crane, t_machine, err in rows:
        print(f"{label:36s} {t_crane * 1e3:11.3f} {t_machine * 1e3:13.3f} {t_machine / t_crane:14.2f} {err:14.1e}")


if __name__ == "__main__":
    main()

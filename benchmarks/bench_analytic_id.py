"""Analytic vs MuJoCo inverse dynamics: time per sample on the same 1000 samples, same run.

Usage: ``.venv/bin/python benchmarks/bench_analytic_id.py [--samples 1000] [--repeats 7]``.
Each path is timed ``repeats`` times on the same samples (the MuJoCo model is built once,
outside the timing, as the optimiser does per link-length set); the best time is reported.
"""

from __future__ import annotations

import argparse

import numpy as np
from timing_helper import best_wall

from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics, spatial_inverse_dynamics
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.validation import random_states


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    crane = load_crane("xs031")
    lengths = crane.default_lengths
    joints = random_states(crane, np.random.default_rng(0), args.samples)
    payload = np.array([0.0, -2452.0, 0.0])
    mujoco = MujocoInverseDynamics(crane, lengths)
    analytic_out = analytic_inverse_dynamics(crane, lengths, joints, tcp_force=payload)
    mujoco_out = mujoco(joints, tcp_force=payload)
    error = np.max(np.abs(analytic_out.force - mujoco_out.force) / np.max(np.abs(analytic_out.force), axis=0))
    t_analytic = best_wall(args.repeats, lambda: analytic_inverse_dynamics(crane, lengths, joints, tcp_force=payload))
    t_spatial = best_wall(args.repeats, lambda: spatial_inverse_dynamics(crane, lengths, joints, tcp_force=payload))
    t_mujoco = best_wall(args.repeats, lambda: mujoco(joints, tcp_force=payload))
    t_build = best_wall(args.repeats, lambda: MujocoInverseDynamics(crane, lengths))
    n = args.samples
    print(f"samples: {n} (random states over the working ranges, 250 kg payload), best of {args.repeats}")
    print(f"analytic ID: {t_analytic * 1e3:8.2f} ms total, {t_analytic / n * 1e6:7.2f} us/sample")
    print(f"6D form:     {t_spatial * 1e3:8.2f} ms total, {t_spatial / n * 1e6:7.2f} us/sample (reference)")
    print(f"MuJoCo ID:   {t_mujoco * 1e3:8.2f} ms total, {t_mujoco / n * 1e6:7.2f} us/sample")
    print(f"MuJoCo model build per link-length set: {t_build * 1e3:.2f} ms (not in the per-sample times)")
    print(f"ratio MuJoCo / analytic: {t_mujoco / t_analytic:.1f}x (goal >= 10x)")
    print(f"max relative force difference: {error:.1e}")


if __name__ == "__main__":
    main()

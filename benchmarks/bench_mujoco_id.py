"""Benchmark: MuJoCo actuator-force computation per trajectory sample vs a bare mj_inverse loop (goal <= 2x).

Run: ``.venv/bin/python benchmarks/bench_mujoco_id.py [--samples N] [--repeat R]``. Prints microseconds per
sample for MujocoInverseDynamics(...)(joints) and for a bare loop (set qpos, qvel, qacc; mj_inverse; copy
qfrc_inverse) on the same model in the same run, their ratio, and the model rebuild time per link-length set.
"""

from __future__ import annotations

import argparse

import mujoco
import numpy as np
from timing_helper import best_wall

from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.model import build_model


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()

    crane = load_crane("xs031")
    low = np.array([crane.lift.joint_range[0], crane.tilt.joint_range[0], crane.telescope.joint_range[0]])
    high = np.array([crane.lift.joint_range[1], crane.tilt.joint_range[1], crane.telescope.joint_range[1]])
    t = np.linspace(0.0, 4.0, args.samples)[:, None]
    w, mid, amp = 2 * np.pi / 4.0, (low + high) / 2, 0.45 * (high - low)
    joints = JointSamples(mid - amp * np.cos(w * t), amp * w * np.sin(w * t), amp * w**2 * np.cos(w * t))

    inverse = MujocoInverseDynamics(crane)
    qpos, qvel, qacc = inverse.state(joints)  # a loop-consistent state for the bare loop
    model, data = inverse.model, mujoco.MjData(inverse.model)
    out = np.empty((args.samples, model.nv))

    def bare() -> None:
        for i in range(args.samples):
            data.qpos[:] = qpos[i]
            data.qvel[:] = qvel[i]
            data.qacc[:] = qacc[i]
            mujoco.mj_inverse(model, data)
            out[i] = data.qfrc_inverse

    n = args.samples
    t_bare = best_wall(args.repeat, bare) / n * 1e6
    t_full = best_wall(args.repeat, lambda: inverse(joints)) / n * 1e6
    t_load = best_wall(args.repeat, lambda: inverse(joints, tcp_force=[0.0, -2000.0, 0.0])) / n * 1e6
    t_state = best_wall(args.repeat, lambda: inverse.state(joints)) / n * 1e6
    rebuild = best_wall(args.repeat * 5, lambda: build_model(crane)) * 1e3
    construct = best_wall(args.repeat * 5, lambda: MujocoInverseDynamics(crane)) * 1e3

    print(f"samples per call                     {n}")
    print(f"bare mj_inverse loop                 {t_bare:8.2f} us/sample")
    print(f"MujocoInverseDynamics(...)(joints)   {t_full:8.2f} us/sample   ratio {t_full / t_bare:.2f}x (goal <= 2x)")
    print(f"  of which loop-consistent state     {t_state:8.2f} us/sample")
    print(f"  with a TCP force                   {t_load:8.2f} us/sample   ratio {t_load / t_bare:.2f}x")
    print(f"model rebuild (build_model)          {rebuild:8.3f} ms")
    print(f"MujocoInverseDynamics construction   {construct:8.3f} ms")


if __name__ == "__main__":
    main()

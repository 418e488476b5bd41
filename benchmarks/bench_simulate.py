"""Time one closed-loop cycle of the default study (optimal design): real-time factor, Python vs MuJoCo.

Usage: ``python benchmarks/bench_simulate.py [RESULT_DIR] [--repeat N]`` (without RESULT_DIR the
default study is optimised first, outside the timing). The cycle is the environment of
:mod:`hiab_sim.env` under the cascade controller, exactly as ``hiab-sim simulate`` runs it. The
split is measured in the same run on the same model: the MuJoCo part is as many ``mj_step`` calls
(and ``mj_kinematics`` per agent step) as the cycle made; the drive part is as many drive steps;
the rest (controller, observations, dm-control) is Python. Best of ``--repeat`` runs, wall clock
and process CPU time (the machine may be shared).
"""

from __future__ import annotations

import argparse

import mujoco
import numpy as np
from timing_helper import best_of

from hiab_sim.env import default_result_dir, make_environment, read_plan
from hiab_sim.env.rollout import run_closed_loop


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "result_dir", nargs="?", help="folder of 'hiab-sim optimize' (default: optimise the default study)"
    )
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    plan = read_plan(args.result_dir or default_result_dir(), "optimal")

    holder: dict[str, object] = {}

    def cycle() -> None:
        run, physics = run_closed_loop(plan)
        holder["run"], holder["physics"] = run, physics

    # The environment is built inside the timed call; its construction is timed on its own too.
    build = best_of(args.repeat, lambda: make_environment(plan).physics.free())
    total = best_of(args.repeat, cycle)
    cycle_time = (total[0] - build[0], total[1] - build[1])
    run, physics = holder["run"], holder["physics"]
    steps = physics.steps  # type: ignore[attr-defined]
    agent_steps = len(run.time) - 1  # type: ignore[attr-defined]
    model, data = physics.model.ptr, physics.data.ptr  # type: ignore[attr-defined]

    def mujoco_only() -> None:
        for _ in range(steps):
            mujoco.mj_step(model, data)
        for _ in range(agent_steps):
            mujoco.mj_kinematics(model, data)

    drives = physics.drives  # type: ignore[attr-defined]
    refs, speeds = np.array([20.0, -10.0, 3.0]), np.array([300.0, -200.0, 100.0])

    def drives_only() -> None:
        for _ in range(steps):
            drives.step(refs, speeds, 1e-3)

    physics.reset()  # type: ignore[attr-defined]
    in_mujoco = best_of(args.repeat, mujoco_only)
    in_drives = best_of(args.repeat, drives_only)
    physics.free()  # type: ignore[attr-defined]
    simulated = float(run.time[-1])  # type: ignore[attr-defined]
    rest = (cycle_time[0] - in_mujoco[0] - in_drives[0], cycle_time[1] - in_mujoco[1] - in_drives[1])
    print(f"closed-loop cycle: {simulated:.2f} s simulated, {steps} physics steps, {agent_steps} agent steps")
    print(f"{'':52s} {'wall [s]':>9s} {'CPU [s]':>9s} {'CPU share':>9s}")
    rows = [
        ("environment build (plan -> ID at 1 kHz -> model)", build),
        ("closed-loop cycle (build excluded)", cycle_time),
        ("  MuJoCo (mj_step, mj_kinematics)", in_mujoco),
        ("  Python: drives (numpy, exact current loops)", in_drives),
        ("  Python: controller, observations, dm-control", rest),
    ]
    for label, (wall, cpu) in rows:
        share = f"{100 * cpu / cycle_time[1]:8.1f}%" if label.startswith("  ") else ""
        print(f"{label:52s} {wall:9.3f} {cpu:9.3f} {share:>9s}")
    wall_factor, cpu_factor = simulated / cycle_time[0], simulated / cycle_time[1]
    print(f"real-time factor of the cycle: {wall_factor:.1f}x (wall), {cpu_factor:.1f}x (CPU)")


if __name__ == "__main__":
    main()

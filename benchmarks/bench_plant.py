"""Time a closed-loop cycle of the default study (optimal design) on the realistic plant: real-time factor, parts.

Usage: ``python benchmarks/bench_plant.py [RESULT_DIR] [--plant realistic|FILE] [--repeat N]`` (without
RESULT_DIR the default study is optimised first, outside the timing). The cycle is exactly what
``hiab-sim simulate --plant realistic`` runs per design and variant. The parts are timed in the same
process on the same Physics, as many calls as the run made (the settled start's hold before the cycle
included, and counted in the simulated time of the real-time factor): MuJoCo's ``mj_step`` (with the drive
train's springs), the discrete current loops, the friction meter, the winding temperature (update and
R_s hand-over), the encoder and delay line; the rest (controller, observations, dm-control, the
drive train's Python side) is the remainder; the environment's build is timed on its own. Best of
``--repeat``, wall clock and process CPU time.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import replace

import mujoco
import numpy as np
from timing_helper import best_of

from hiab_sim.env import default_result_dir, make_environment, read_plan
from hiab_sim.env.plant import load_plant
from hiab_sim.env.rollout import run_closed_loop


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("result_dir", nargs="?", help="folder of 'hiab-sim optimize' (default: the default study)")
    parser.add_argument("--plant", default="realistic")
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    plan = read_plan(args.result_dir or default_result_dir(), "optimal")
    plant = load_plant(args.plant)
    holder: dict[str, object] = {}

    def cycle() -> None:
        run, physics = run_closed_loop(plan, plant=plant)
        holder["run"], holder["physics"] = run, physics

    build = best_of(args.repeat, lambda: make_environment(plan, plant=plant).physics.free())
    total = best_of(args.repeat, cycle)
    total = (total[0] - build[0], total[1] - build[1])
    run, physics = holder["run"], holder["physics"]
    model, data = physics.model.ptr, physics.data.ptr  # type: ignore[attr-defined]
    h = float(model.opt.timestep)
    # the run simulates the settled start's hold (settle_time_s) before the cycle; its steps count too
    held = float(run.settle_time_s)  # type: ignore[attr-defined]
    steps = physics.steps + round(held / h)  # type: ignore[attr-defined]
    drives = physics.drives  # type: ignore[attr-defined]
    refs, speeds = np.array([20.0, -10.0, 3.0]), np.array([300.0, -200.0, 100.0])
    parts: list[tuple[str, Callable[[], object]]] = [
        ("MuJoCo (mj_step)", lambda: [mujoco.mj_step(model, data) for _ in range(steps)]),
        ("current loops (discrete, Python)", lambda: [drives.step(refs, speeds, h) for _ in range(steps)]),
    ]
    friction = physics.friction  # type: ignore[attr-defined]
    if friction is not None:
        parts.append(("friction meter", lambda: [friction.power(model, data) for _ in range(steps)]))
    thermal = physics.thermal  # type: ignore[attr-defined]
    if thermal is not None:

        def heat() -> None:
            for _ in range(steps):
                thermal.advance(np.full(3, 0.1), h)
                drives.drives = replace(drives.drives, resistance=thermal.resistance())

        parts.append(("winding temperature, R_s", heat))
    sensor = physics.sensor  # type: ignore[attr-defined]
    parts.append(("encoder and delay", lambda: [sensor.push(*physics.motor_state()) for _ in range(steps)]))  # type: ignore[attr-defined]
    timed = [(label, best_of(args.repeat, fn)) for label, fn in parts]
    physics.free()  # type: ignore[attr-defined]
    simulated = float(run.time[-1]) + held  # type: ignore[attr-defined]
    print(
        f"{plant.name} plant, effects {', '.join(plant.enabled)}: {simulated:.2f} s simulated "
        f"({held:.2f} s settled start + the cycle), {steps} physics steps"
    )
    print(f"{'':44s} {'wall [s]':>9s} {'CPU [s]':>9s} {'CPU share':>9s}")
    print(f"{'environment build (plan -> ID at 1 kHz -> model)':44s} {build[0]:9.3f} {build[1]:9.3f}")
    print(f"{'closed-loop cycle (build excluded)':44s} {total[0]:9.3f} {total[1]:9.3f}")
    rest = (total[0] - sum(t[0] for _, t in timed), total[1] - sum(t[1] for _, t in timed))
    for label, (wall, cpu) in [*timed, ("rest: controller, dm-control, drive train", rest)]:
        print(f"  {label:42s} {wall:9.3f} {cpu:9.3f} {100 * cpu / total[1]:8.1f}%")
    print(f"real-time factor: {simulated / total[0]:.2f}x (wall), {simulated / total[1]:.2f}x (CPU)")


if __name__ == "__main__":
    main()

"""Time a closed-loop cycle of the default study (optimal design) on the realistic plant: real-time factor, parts.

Usage: ``python benchmarks/bench_plant.py [RESULT_DIR] [--plant realistic|FILE] [--repeat N]`` (without
RESULT_DIR the default study is optimised first, outside the timing). The run is exactly what
``hiab-sim simulate --plant realistic`` runs per design and variant (:func:`hiab_sim.env.rollout.run_closed_loop`),
in four phases: the environment's build (plan -> inverse dynamics at 1 kHz -> model, the plan's hot
windings), the loop design, **the cycle** (the settled start's hold and the cycle, the physics steps
the real-time factor counts) and the planner's energy of the plan on a 5 ms grid (a prediction the
report compares with, not part of the cycle).

Totals are the best of ``--repeat`` uninstrumented runs, wall clock and process CPU time. The shares
come from one more run of the same cycle with every part timed where it is called, exclusive of the
parts it calls (a part inside another counts once, in itself): MuJoCo (``mj_step``, ``mj_kinematics``),
the current loops, the EMLA file's drive losses, the drive train's Python side, the friction meter,
the winding temperature and its R_s hand-over, the sensors, the controller, the observations; the rest
is dm-control's step and the Physics's own loop (indexing, energy booking). The timers cost about
1 us per call, which the instrumented run's total shows against the uninstrumented one.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import time
from collections.abc import Callable, Iterator
from typing import Any

import mujoco
from timing_helper import best_of

import hiab_sim.env.physics as physics_module
import hiab_sim.env.rollout as rollout
from hiab_sim.control.cascade import CascadeController
from hiab_sim.env import default_result_dir, read_plan
from hiab_sim.env.plant import load_plant
from hiab_sim.env.task import CraneTrackingTask


class PartTimer:
    """Exclusive wall-clock seconds and calls per part; a part's time excludes the timed parts it calls."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}
        self.calls: dict[str, int] = {}
        self._stack: list[list[float]] = []  # per open part: [start, time of its timed children]

    def wrap(self, part: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        """``fn`` timed as ``part``."""

        def timed(*args: Any, **kwargs: Any) -> Any:
            frame = [time.perf_counter(), 0.0]
            self._stack.append(frame)
            try:
                return fn(*args, **kwargs)
            finally:
                elapsed = time.perf_counter() - frame[0]
                self._stack.pop()
                if self._stack:
                    self._stack[-1][1] += elapsed
                self.seconds[part] = self.seconds.get(part, 0.0) + elapsed - frame[1]
                self.calls[part] = self.calls.get(part, 0) + 1

        return timed


@contextlib.contextmanager
def patched(targets: list[tuple[object, str, str]], timer: PartTimer) -> Iterator[None]:
    """Replace ``owner.attribute`` by its timed version (as ``part``) for the block; restore after."""
    saved = []
    for owner, attribute, part in targets:
        original = getattr(owner, attribute)
        saved.append((owner, attribute, original))
        setattr(owner, attribute, timer.wrap(part, original))
    try:
        yield
    finally:
        for owner, attribute, original in reversed(saved):
            setattr(owner, attribute, original)


PHASES = [
    (rollout, "make_environment", "build"),
    (rollout, "design_loop", "loop design"),
    (rollout, "run_environment", "cycle"),
    (rollout, "resampled_prediction", "prediction on 5 ms"),
]

#: Parts of the cycle, patched on their classes or modules (instances are made inside the run).
CLASS_PARTS = [
    (mujoco, "mj_step", "MuJoCo (mj_step, mj_kinematics)"),
    (mujoco, "mj_kinematics", "MuJoCo (mj_step, mj_kinematics)"),
    (CascadeController, "__call__", "controller"),
    (CascadeController, "hold", "controller"),
    (CraneTrackingTask, "get_observation", "observations"),
    (physics_module, "coupled_step", "drive train (Python side)"),
    (physics_module, "replace", "winding temperature, R_s hand-over"),
]

#: Parts patched on the Physics's own objects once the environment is built: (attribute path, methods, part).
INSTANCE_PARTS = [
    ("drives", ("step",), "current loops"),
    ("losses", ("dc_energy", "loss_torque", "rigid_rod_force"), "drive losses (inverter, brake, screw)"),
    ("drive_train", ("spring_force", "rod_actuator", "step"), "drive train (Python side)"),
    ("friction", ("power",), "friction meter"),
    ("thermal", ("advance", "resistance"), "winding temperature, R_s hand-over"),
    ("sensor", ("push", "measured"), "sensors (encoder, delay, current errors)"),
    ("current_error", ("sample",), "sensors (encoder, delay, current errors)"),
]


def instrumented_run(plan: Any, plant: Any) -> tuple[PartTimer, Any]:
    """One run of the cycle with every part timed (module docstring); returns the timer and the run."""
    timer = PartTimer()
    build = rollout.make_environment

    def build_and_instrument(*args: Any, **kwargs: Any) -> Any:
        env = build(*args, **kwargs)
        physics = env.physics
        for holder, methods, part in INSTANCE_PARTS:
            owner = getattr(physics, holder, None)
            for method in methods:
                if owner is not None and hasattr(owner, method):
                    setattr(owner, method, timer.wrap(part, getattr(owner, method)))
        return env

    with patched(PHASES, timer), patched(CLASS_PARTS, timer):
        original = rollout.make_environment
        rollout.make_environment = timer.wrap("build", build_and_instrument)
        try:
            run, physics = rollout.run_closed_loop(plan, plant=plant)
        finally:
            rollout.make_environment = original
    physics.free()
    return timer, run


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("result_dir", nargs="?", help="folder of 'hiab-sim optimize' (default: the default study)")
    parser.add_argument("--plant", default="realistic")
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    plan = read_plan(args.result_dir or default_result_dir(), "optimal")
    plant = load_plant(args.plant)
    load = os.getloadavg()[0]

    phase_walls: dict[str, list[float]] = {}
    phase_cpus: dict[str, list[float]] = {}
    holder: dict[str, Any] = {}

    def phase_timed(fn: Callable[..., Any], label: str) -> Callable[..., Any]:
        def timed(*a: Any, **k: Any) -> Any:
            w, c = time.perf_counter(), time.process_time()
            try:
                return fn(*a, **k)
            finally:
                phase_walls.setdefault(label, []).append(time.perf_counter() - w)
                phase_cpus.setdefault(label, []).append(time.process_time() - c)

        return timed

    def full_run() -> None:
        run, physics = rollout.run_closed_loop(plan, plant=plant)
        holder["run"] = run
        physics.free()

    saved = [(owner, attribute, getattr(owner, attribute)) for owner, attribute, _ in PHASES]
    for owner, attribute, label in PHASES:
        setattr(owner, attribute, phase_timed(getattr(owner, attribute), label))
    try:
        total = best_of(args.repeat, full_run)
    finally:
        for owner, attribute, original in saved:
            setattr(owner, attribute, original)
    timer, _ = instrumented_run(plan, plant)

    run = holder["run"]
    held = float(run.settle_time_s)
    simulated = float(run.time[-1]) + held
    cycle_calls = timer.calls.get("current loops", 0)
    print(
        f"{plant.name} plant, effects {', '.join(plant.enabled)}: {simulated:.2f} s simulated "
        f"({held:.2f} s settled start + the cycle), {cycle_calls} physics steps; load average {load:.1f} "
        f"on {os.cpu_count()} cores"
    )
    print(f"{'phase (best of ' + str(args.repeat) + ')':52s} {'wall [s]':>9s} {'CPU [s]':>9s}")
    for _, _, label in PHASES:
        print(f"{label:52s} {min(phase_walls[label]):9.3f} {min(phase_cpus[label]):9.3f}")
    print(f"{'whole run (run_closed_loop)':52s} {total[0]:9.3f} {total[1]:9.3f}")
    cycle_wall, cycle_cpu = min(phase_walls["cycle"]), min(phase_cpus["cycle"])
    print(f"real-time factor of the cycle: {simulated / cycle_wall:.2f}x (wall), {simulated / cycle_cpu:.2f}x (CPU)")
    print(f"real-time factor of the whole run: {simulated / total[0]:.2f}x (wall), {simulated / total[1]:.2f}x (CPU)")
    outside = {"build", "loop design", "prediction on 5 ms"}
    parts = {k: v for k, v in timer.seconds.items() if k not in outside}
    instrumented_cycle = sum(parts.values())
    print(f"\nshare of the cycle per part (one instrumented run, cycle {instrumented_cycle:.3f} s wall)")
    print(f"{'part':52s} {'wall [s]':>9s} {'calls':>8s} {'share':>7s}")
    parts["rest: dm-control, the Physics's loop"] = parts.pop("cycle", 0.0)
    for part, seconds in sorted(parts.items(), key=lambda item: -item[1]):
        calls = timer.calls.get(part, 1)
        print(f"{part:52s} {seconds:9.3f} {calls:8d} {100 * seconds / instrumented_cycle:6.1f}%")


if __name__ == "__main__":
    main()

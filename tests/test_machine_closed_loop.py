"""A machine file's design in closed loop: the excavator (a four-bar bucket) tracks its plan on the ideal plant.

The plan comes from a tiny excavator study (a 4 s rest-to-rest joint move with 50 kg at the TCP);
the closed loop is the generic MJCF per design with the EMLA drives' current dynamics and the cascade
controller (:mod:`hiab_sim.env.machine_env`), time-stepped at 1 ms. Its energy is the drives' exact
per-step integral, the plan's the optimiser's quadrature of its steady-state P_elec: two different
computations of one quantity.
"""

from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from machine_result_helper import held_stroke_drift

from hiab_sim.cli import main
from hiab_sim.cli.simulate import ENERGY_TOLERANCE, TCP_MAX_MM
from hiab_sim.env.machine_env import machine_environment, machine_load_mass, run_machine_closed_loop
from hiab_sim.env.machine_plan import MachinePlan
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics

#: Tracking of the plan's own TCP on the planner's model [mm]: only the loops' residual (measured 0.04 mm).
PLAN_TCP_MAX_MM = 0.5


@pytest.mark.sim
def test_excavator_closed_loop_tracks_the_plan_and_uses_its_energy(excavator_plan: MachinePlan) -> None:
    """Ideal plant = the planner's model: the energy within the CLI's 2 % and the TCP on the plan's path.

    2 % is the closed-loop check of ``hiab-sim simulate`` (and the issue's); on the planner's own
    model the difference is the feedback's work on the loops' residual plus the plan's trapezoid
    quadrature on its 1/12 s grid, measured 0.003 % in total and below 0.2 % on the smallest drive.
    """
    run, physics = run_machine_closed_loop(excavator_plan)
    physics.free()
    summary: Any = run.summary()
    assert run.actuator_names == ("boom", "arm", "bucket")
    assert abs(summary["energy_difference_percent"]) < 100 * ENERGY_TOLERANCE
    for name, drive in summary["actuators"].items():
        predicted = drive["predicted_net_electrical_energy_J"]
        assert drive["net_electrical_energy_J"] == pytest.approx(predicted, rel=ENERGY_TOLERANCE), name
    assert summary["tcp_error_to_plan_mm"]["max"] < PLAN_TCP_MAX_MM
    assert summary["tcp_error_mm"]["max"] < TCP_MAX_MM
    assert summary["current_limit_fraction"] == 0.0 and summary["voltage_limit_fraction"] == 0.0
    assert run.time[-1] == pytest.approx(excavator_plan.duration, abs=0.01)


@pytest.mark.sim
def test_load_mass_is_twice_the_kinetic_energy_of_a_unit_slide_rate(excavator_plan: MachinePlan) -> None:
    """m_L,a from G^T M G against mj_energyVel of the machine moving slide a at 1 m/s, the others held."""
    env = machine_environment(excavator_plan)
    mass = machine_load_mass(excavator_plan, env.task.motion)
    env.physics.free()
    dynamics = MujocoMachineDynamics(excavator_plan.machine)
    k = len(excavator_plan.time) // 2
    q = excavator_plan.position[k]
    n = len(q)
    # the slide rates of unit joint rates, column j: by central differences of the strokes in q
    jx = np.empty((n, n))
    zeros = np.zeros((2, n))
    for j in range(n):
        h = 1e-6
        rows = np.stack([q + h * np.eye(n)[j], q - h * np.eye(n)[j]])
        stroke = dynamics(rows, zeros, zeros).stroke
        jx[:, j] = (stroke[0] - stroke[1]) / (2 * h)
    grid = excavator_plan.time - excavator_plan.time[0]
    index = int(np.argmin(np.abs(env.task.motion.time - grid[k])))
    for a in range(n):
        rate = np.linalg.solve(jx, np.eye(n)[a])
        kinetic, _ = dynamics.energy(q[None], rate[None])
        assert mass[index, a] == pytest.approx(2.0 * kinetic[0], rel=1e-5)


def _open_loop_drift(plan: MachinePlan, with_load: bool) -> float:
    """Largest stroke change [m] over 0.2 s at the first sample's feedforward current, no feedback."""
    env = machine_environment(plan)
    if not with_load:
        env.physics.tcp_load = None
    return held_stroke_drift(env, env.task.motion.current[0])


@pytest.mark.sim
def test_the_tcp_load_holds_the_start_on_the_planners_model(excavator_plan: MachinePlan) -> None:
    """Feedforward current and the plan's TCP force hold the start pose in equilibrium; without the force it sags."""
    held = _open_loop_drift(excavator_plan, with_load=True)
    unloaded = _open_loop_drift(excavator_plan, with_load=False)
    assert held < 1e-5  # [m]
    assert unloaded > 100 * held


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs Debian ffmpeg (scripts/setup.sh installs it)")
def test_simulate_cli_on_a_machine_result(
    excavator_result: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Both designs in closed loop: simulation.json per chain, and closed_loop.mp4 of the machine at 30 fps."""
    import mediapy

    from hiab_sim.env.machine_plan import read_machine_plan
    from hiab_sim.env.validation import VIEWPORT, closed_loop_frame_times

    out = tmp_path / "sim"
    code = main(["simulate", str(excavator_result), "--no-figures", "--quiet", "--out", str(out)])
    assert code == 0
    report = json.loads((out / "simulation.json").read_text(encoding="utf-8"))
    assert set(report["designs"]) == {"initial", "optimal"}
    for entry in report["designs"].values():
        assert abs(entry["energy_difference_percent"]) < 100 * ENERGY_TOLERANCE
        assert set(entry["actuators"]) == {"boom", "arm", "bucket"}
        assert abs(entry["battery_energy_difference_percent"]) < 100 * ENERGY_TOLERANCE  # through the same battery
    assert "DC input" in report["settings"]["energy"]
    assert "closed loop uses" in capsys.readouterr().out
    video = mediapy.read_video(out / "closed_loop.mp4")
    duration = read_machine_plan(excavator_result, "optimal").time[-1]
    assert video.shape[:3] == (len(closed_loop_frame_times(duration)), VIEWPORT[1], VIEWPORT[0])
    assert np.mean(np.abs(video[0].astype(float) - video[-1].astype(float))) > 0.5  # the machine moved
    args = ["simulate", str(excavator_result), "--quiet", "--out", str(out), "--payload-error", "0.2", "--no-video"]
    assert main(args) == 2
    assert "payload-error" in capsys.readouterr().err


def test_refusals_name_the_option() -> None:
    """What a machine file's closed loop does not simulate is refused naming the option; the plant is not refused."""
    from hiab_sim.cli.simulate_machine import refuse_crane_only

    refuse_crane_only(argparse.Namespace(payload_error=0.0, cycles=3, no_video=False))
    with pytest.raises(InvalidInputError, match="payload-error"):
        refuse_crane_only(argparse.Namespace(payload_error=0.2, cycles=1, no_video=True))


@pytest.mark.sim
def test_xs031_machine_file_tracks_as_the_crane_file_does(tmp_path: Path) -> None:
    """The XS 031 machine file's closed loop has the crane file's TCP error: its TCP sits 9.23 mm out of the plane.

    One tiny spiral study on the crane file and on the machine file (the same crane); the built crane's
    plan (the initial design, the same on both) in closed loop. The reference is the path in the plane
    the TCP moves in (at its out-of-plane coordinate), so the two errors agree to a few micrometres
    (measured 1.4 um; the crane's 0.14 / 0.34 mm rms / max); a reference in the mechanism's plane
    would miss by 9.23 mm at every step.
    """
    from test_study_small import TINY, machine_form, small_study, write_study

    from hiab_sim.env.machine_plan import read_machine_plan
    from hiab_sim.env.plan import read_plan
    from hiab_sim.env.rollout import run_closed_loop
    from hiab_sim.study.run import run_study
    from hiab_sim.study.spec.study_file import load_study

    crane_study = small_study(**TINY)
    machine_study = machine_form(crane_study)
    for name, study in (("crane", crane_study), ("machine", machine_study)):
        path = write_study(tmp_path, study, f"{name}.yaml")
        run_study(load_study(path), tmp_path / name, figures=False, progress=None, cross=False)
    crane_run, crane_physics = run_closed_loop(read_plan(tmp_path / "crane", "initial"))
    machine_run, machine_physics = run_machine_closed_loop(read_machine_plan(tmp_path / "machine", "initial"))
    crane_physics.free()
    machine_physics.free()
    assert crane_run.tcp_error.max() < 1e-3  # the crane file's own tracking, within a millimetre
    np.testing.assert_allclose(machine_run.tcp_error, crane_run.tcp_error, rtol=0, atol=2e-5)

"""The realistic plant on a machine file: the excavator's short move on every effect, its pins' friction, its mismatch.

The plan comes from a short excavator study (a 1.5 s rest-to-rest joint move with 50 kg at the
TCP, about 10 s to optimise); the closed loop is :mod:`hiab_sim.env.machine_env` with the plant of
:mod:`hiab_sim.env.plant` built on the machine description's own actuators, joints and loop pins.
"""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
import yaml

from hiab_sim.cli import main
from hiab_sim.crane.description import Crane
from hiab_sim.env.effects import true_mass_prediction
from hiab_sim.env.machine_env import machine_environment, run_machine_closed_loop
from hiab_sim.env.machine_plan import MachinePlan, read_machine_plan
from hiab_sim.env.plant import EFFECTS, load_plant
from hiab_sim.env.plant.config import JointFriction, Plant
from hiab_sim.env.plant.friction import FrictionMeter, add_joint_friction
from hiab_sim.env.plant.mismatch import true_machine
from hiab_sim.env.rollout import ClosedLoopRun
from hiab_sim.machine.dynamics.mjcf_build import spec_of_tree
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.dynamics.tree import machine_tree
from hiab_sim.resources import locate

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine_result_helper import EXCAVATOR_STUDY, held_stroke_drift, joint_csv, solved_study

REALISTIC = load_plant("realistic")
#: The issue's bound on the TCP tracking error of the realistic plant [mm].
TCP_MAX_MM = 10.0
DURATION = 1.5  # [s]
#: The short study: the helper's excavator study on a 1.5 s move (0.15 / 0.15 / 0.2 rad).
SHORT_STUDY = {
    **EXCAVATOR_STUDY,
    "name": "excavator_short_move",
    "spline": {"control_points": 8, "degree": 5},
    "grid": {"duration": DURATION, "intervals": 6, "fine_factor": 4},
}


@pytest.fixture(scope="module")
def result(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("excavator_plant")
    joint_csv(folder / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.15, -1.65, -0.8], DURATION)
    (folder / "study.yaml").write_text(yaml.safe_dump(SHORT_STUDY), encoding="utf-8")
    return solved_study(folder)


@pytest.fixture(scope="module")
def plan(result: Path) -> MachinePlan:
    return read_machine_plan(result, "optimal")


def _run(plan: MachinePlan, plant: Plant | None, cycles: int = 1) -> ClosedLoopRun:
    run, physics = run_machine_closed_loop(plan, plant=plant, cycles=cycles)
    physics.free()
    return run


@pytest.fixture(scope="module")
def today(plan: MachinePlan) -> ClosedLoopRun:
    """The machine's closed loop without a plant."""
    return _run(plan, None)


def _only_mismatch(**errors: Any) -> Plant:
    """The realistic plant with only the mismatch on, every error zero but ``errors``."""
    zero = dict(end_mass_error=0.0, end_mass_com_offset_m=(0.0, 0.0, 0.0), link_mass_error=0.0, link_com_shift_m=0.0)
    zero.update(friction_error=0.0, **errors)
    return dataclasses.replace(REALISTIC, mismatch=dataclasses.replace(REALISTIC.mismatch, **zero)).only("mismatch")


@pytest.mark.sim
def test_ideal_plant_reproduces_the_machines_closed_loop_exactly(plan: MachinePlan, today: ClosedLoopRun) -> None:
    """Every effect off gives the machine's closed loop without a plant, sample for sample."""
    ideal = _run(plan, REALISTIC.ideal())
    assert ideal.net_energy == today.net_energy
    np.testing.assert_array_equal(ideal.tcp_error, today.tcp_error)
    np.testing.assert_array_equal(ideal.current_dq, today.current_dq)
    assert ideal.gains == today.gains


@pytest.mark.sim
@pytest.mark.parametrize("effect", EFFECTS)
def test_each_effect_alone_completes_the_cycle_and_tracks(plan: MachinePlan, today: ClosedLoopRun, effect: str) -> None:
    """With one effect on, the excavator's cycle completes within 10 mm of the reference at -2 % to +80 % energy."""
    run = _run(plan, REALISTIC.only(effect))
    assert run.time[-1] == pytest.approx(today.time[-1])
    assert 1000.0 * run.tcp_error.max() < TCP_MAX_MM
    assert -0.02 < run.bus_energy / today.net_energy - 1.0 < 0.8
    if effect == "joint_friction":
        assert run.friction_loss > 0.0
    if effect == "drive_train":
        assert run.drive_train_loss is not None and run.drive_train_loss.sum() > 0.0
        assert run.lowest_resonance_hz is not None  # the gains were designed against the locked-rod mode


def test_friction_sits_on_every_hinge_and_each_loop_pins_relative_rotation(plan: MachinePlan) -> None:
    """The machine's joints get the hinge friction, every chain hinge the pin friction; each tendon is a pin's rate.

    The tendon rate (MuJoCo's ``ten_velocity``) equals body b's angular rate minus body a's about
    the plane's normal, read from MuJoCo's own body velocities (``cvel``), at random joint rates.
    """
    tree = machine_tree(plan.machine)
    spec = spec_of_tree(tree)
    joints, tendons = add_joint_friction(spec, JointFriction(True, 150.0, 50.0, 100.0, 20.0), plan.machine.joint_names)
    model = spec.compile()
    hinges = {model.joint(j).name for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE}
    assert set(joints) == hinges and len(tendons) == len(tree.loops)
    for name in joints:
        expected = 150.0 if name in plan.machine.joint_names else 100.0
        assert model.dof_frictionloss[model.jnt_dofadr[model.joint(name).id]] == expected
    data = mujoco.MjData(model)
    data.qvel[:] = np.random.default_rng(3).normal(size=model.nv)
    mujoco.mj_forward(model, data)
    normal = data.xaxis[model.joint(plan.machine.joint_names[0]).id]
    for loop, name in zip(tree.loops, tendons, strict=True):
        omega = [data.cvel[model.site(f"{loop.name}.{end}").bodyid[0], :3] @ normal for end in ("a", "b")]
        assert data.ten_velocity[model.tendon(name).id] == pytest.approx(omega[1] - omega[0], abs=1e-12)


def test_true_mass_prediction_without_errors_is_the_plans_prediction(plan: MachinePlan) -> None:
    """Zero errors: MuJoCo ID of the machine + the planner's EMLA model = the optimiser's energy (1e-3).

    The optimiser's number is its own inverse dynamics (the study's ID path) on its fine grid: an
    independent computation of the same quantity. A heavier payload costs more.
    """
    assert true_mass_prediction(plan, _only_mismatch()) == pytest.approx(plan.predicted_net_energy, rel=1e-3)
    assert true_mass_prediction(plan, _only_mismatch(end_mass_error=0.5)) > plan.predicted_net_energy


def test_true_machine_scales_every_moving_part_by_the_link_error(plan: MachinePlan) -> None:
    """The MuJoCo model of the true machine weighs (1 + e_link) times the planned one, body by body."""
    mismatch = _only_mismatch(link_mass_error=0.03).mismatch
    planned = spec_of_tree(machine_tree(plan.machine)).compile()
    true = spec_of_tree(machine_tree(true_machine(plan.machine, mismatch))).compile()
    np.testing.assert_allclose(true.body_mass, 1.03 * planned.body_mass, rtol=1e-12)


def _drift(plan: MachinePlan, plant: Plant, current: np.ndarray) -> float:
    """Largest stroke change [m] over 0.2 s holding the start at ``current`` [A], no feedback."""
    return held_stroke_drift(machine_environment(plan, plant=plant), current)


@pytest.mark.sim
def test_a_heavier_payload_is_held_by_the_current_of_its_inverse_dynamics(plan: MachinePlan) -> None:
    """The simulated payload (1 + e) P: the planned feedforward sags, the one of (1 + e) P in the MuJoCo ID holds.

    The holding current comes from the machine's inverse dynamics with the TCP force F + e P
    (:class:`~hiab_sim.machine.dynamics.mujoco_path.MujocoMachineDynamics`) through the planner's
    steady-state drive (:func:`hiab_sim.emla.drive.drive_state`): an independent path to the load
    the simulation applies (:class:`~hiab_sim.env.tcp_load.TcpLoad`).
    """
    from hiab_sim.emla.drive import drive_state

    heavier = _only_mismatch(end_mass_error=0.5)
    planned = machine_environment(plan).task.motion.current[0]
    force = plan.tcp_force[:1] + 0.5 * plan.payload_force[:1]
    zero = np.zeros((1, plan.position.shape[1]))
    samples = MujocoMachineDynamics(plan.machine)(plan.position[:1], zero, zero, tcp_force=force[:, :2])
    held = np.array([float(drive_state(p, samples.force[0, i], 0.0, 0.0).i_q) for i, p in enumerate(plan.emlas)])
    assert _drift(plan, heavier, held) < 1e-5  # [m]
    assert _drift(plan, heavier, planned) > 100 * _drift(plan, heavier, held)


def _plant_file(path: Path, effects: tuple[str, ...]) -> Path:
    """The realistic preset with only ``effects`` enabled, written to ``path``."""
    data = yaml.safe_load(locate("realistic", "plant").read_text())
    for name in EFFECTS:
        data[name]["enabled"] = name in effects
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


@pytest.mark.e2e
def test_simulate_runs_the_effect_study_on_a_machine_result(
    result: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``simulate --plant FILE`` on a machine result: the plant's run, the ideal one, the share, the re-plan.

    One effect (the mismatch) keeps the command short: two variants per design and one re-plan.
    """
    plant = _plant_file(tmp_path / "plant.yaml", ("mismatch",))
    out = tmp_path / "sim"
    args = ["simulate", str(result), "--plant", str(plant), "--no-video", "--no-figures", "--quiet", "--out", str(out)]
    assert main(args) == 0
    report = json.loads((out / "simulation.json").read_text(encoding="utf-8"))
    effects = report["plant_effects"]
    assert list(effects["variants"]) == ["ideal", "mismatch"]
    for variant in effects["variants"].values():
        for design in ("initial", "optimal"):
            assert variant[design]["tcp_error_mm"]["max"] < TCP_MAX_MM
        assert isinstance(variant["optimal_below_initial"], bool)
    ideal = effects["variants"]["ideal"]
    for design, entry in report["designs"].items():  # the plant's run is the report's own
        assert effects["variants"]["mismatch"][design]["dc_bus_energy_J"] == entry["dc_bus_energy_J"]
        assert ideal[design]["dc_bus_energy_J"] < entry["dc_bus_energy_J"]
    assert effects["share_of_energy_difference"]["optimal"] == {"mismatch": 1.0}
    split = effects["mismatch_split"]["optimal"]
    assert split["predicted_at_true_masses_J"] > split["predicted_J"]
    assert split["replanned_optimum_predicted_J"] > 0.0
    printed = capsys.readouterr().out
    assert "| mismatch | optimal |" in printed and "re-planned for the true masses" in printed
    compact = (out / "effects.md").read_text(encoding="utf-8").split("\n\n")[1].splitlines()
    assert compact[0] == "| effect | ideal | mismatch |" and len(compact) == 5
    tcp = effects["variants"]["mismatch"]["optimal"]["tcp_error_mm"]["max"]
    assert compact[3].endswith(f"/ {tcp:.2f} |")


def test_a_bad_plant_on_a_machine_result_exits_2_and_writes_nothing(
    result: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--plant`` is read where the machine's own realistic plant is known: a bad one is one line, no folder."""
    out = tmp_path / "sim"
    assert main(["simulate", str(result), "--plant", "windy", "--no-video", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "windy" in err and "\n" not in err and "Traceback" not in err
    assert not out.exists()


def test_the_xs031_machine_file_gets_the_crane_files_friction(crane: Crane) -> None:
    """The XS 031 as a machine file and as the crane file: the same hinges, pins and loop-pin tendons, valued alike."""
    from hiab_sim.machine.loader import load_machine
    from hiab_sim.model.mjcf import JOINTS, build_spec

    friction = JointFriction(True, 150.0, 50.0, 100.0, 20.0)
    machine = load_machine("xs031")
    counts = []
    for spec, hinges in ((spec_of_tree(machine_tree(machine)), machine.joint_names), (build_spec(crane), JOINTS)):
        joints, tendons = add_joint_friction(spec, friction, hinges)
        model = spec.compile()
        values = sorted(float(model.dof_frictionloss[model.jnt_dofadr[model.joint(j).id]]) for j in joints)
        counts.append((values, len(tendons), sorted(np.abs(FrictionMeter(model, joints, tendons).tendon_rows).sum(1))))
    assert counts[0] == counts[1] == ([100.0, 100.0, 150.0, 150.0], 2, [2.0, 2.0])

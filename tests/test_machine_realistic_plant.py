"""Each machine's realistic plant: the excavator's own file, its friction from its own pin loads, the XS 031's default.

``hiab-sim simulate RUN --plant realistic`` on a machine file's result reads the plant the machine
file names (``realistic_plant``); the excavator's (``plant_realistic_exact.yaml``) is the shipped
realistic plant with the hinge and pin friction mu r F of the arm's own pin loads and the digging
duty's rest. The friction values are checked here against the pin loads they were derived from.
"""

from __future__ import annotations

import dataclasses
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from hiab_sim.env.plant import load_plant
from hiab_sim.env.plant.load import machine_plant
from hiab_sim.errors import ConfigError
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.machine.loader import load_machine
from hiab_sim.structure.machine_structure import machine_pin_loads
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.report.design_check import fine_problem
from hiab_sim.study.spec.study_file import load_study

#: The file's friction rule: mu = 0.1 and a 20 mm pin radius (plant_realistic_exact.yaml's sources).
FRICTION_COEFFICIENT = 0.1
PIN_RADIUS_M = 0.020


def test_the_excavators_realistic_plant_differs_from_the_shipped_one_only_where_the_machine_enters() -> None:
    """Friction and the rest between cycles are the excavator's; every other section is the shipped plant's."""
    shipped = load_plant("realistic")
    own = machine_plant("realistic", load_machine("exact").realistic_plant)
    assert own.name == "realistic_exact"
    assert own.joint_friction != shipped.joint_friction
    assert own.joint_friction.hinge_coulomb_N_m < shipped.joint_friction.hinge_coulomb_N_m
    assert own.thermal == dataclasses.replace(shipped.thermal, rest_between_cycles_s=own.thermal.rest_between_cycles_s)
    for section in ("drive_train", "sensors", "current_loop", "mismatch"):
        assert getattr(own, section) == getattr(shipped, section), section
    assert machine_plant("ideal", load_machine("exact").realistic_plant).enabled == ()


def test_the_rest_between_cycles_is_the_digging_studys_duty() -> None:
    """The excavator plant's rest after each cycle is exact_digging's duty rest (the thermal state over cycles)."""
    own = machine_plant("realistic", load_machine("exact").realistic_plant)
    assert own.thermal.rest_between_cycles_s == load_study("exact_digging").energy.duty.rest_time


def test_machine_show_names_the_realistic_plant() -> None:
    """``machine show`` says which plant ``simulate --plant realistic`` reads for the machine."""
    from hiab_sim.cli.machine import describe

    assert describe(load_machine("exact"))[-1] == "realistic plant (simulate --plant realistic): realistic_exact"
    last = describe(load_machine("xs031"))[-1]
    assert last.endswith("realistic (the shipped plant: the XS 031's estimates; this file names none)")


def test_the_xs031_machine_file_keeps_the_shipped_realistic_plant() -> None:
    """A machine file that names no realistic plant gets the shipped one (the XS 031's estimates)."""
    assert load_machine("xs031").realistic_plant is None
    assert machine_plant("realistic", None) == load_plant("realistic")


def test_a_relative_realistic_plant_is_read_next_to_the_machine_file(tmp_path: Path) -> None:
    """``realistic_plant: mine.yaml`` in a user's machine file is the file beside it, whatever the working folder."""
    presets = resources.files("hiab_sim") / "presets"
    text = (presets / "exact_excavator.yaml").read_text(encoding="utf-8")
    assert "realistic_plant: realistic_exact\n" in text
    (tmp_path / "arm.yaml").write_text(text.replace("realistic_plant: realistic_exact", "realistic_plant: mine.yaml"))
    plant_text = (presets / "plant_realistic.yaml").read_text(encoding="utf-8")
    (tmp_path / "mine.yaml").write_text(plant_text.replace("value: 150.0", "value: 12.5", 1), encoding="utf-8")
    machine = load_machine(tmp_path / "arm.yaml", check_assembly=False)
    assert machine.realistic_plant == str((tmp_path / "mine.yaml").resolve())
    plant = machine_plant("realistic", machine.realistic_plant)
    assert plant.name == "mine" and plant.joint_friction.hinge_coulomb_N_m == 12.5
    (tmp_path / "mine.yaml").unlink()
    with pytest.raises(ConfigError, match=r"^realistic_plant: cannot read plant 'mine.yaml'"):
        load_machine(tmp_path / "arm.yaml", check_assembly=False)


@pytest.fixture(scope="module")
def pin_means() -> dict[str, tuple[str, float]]:
    """Mean pin-load magnitude [N] over exact_digging's fine grid at the machine file's design, with each pin's kind."""
    study = load_study("exact_digging")
    problem = StudyProblem(study)
    fine = fine_problem(problem.problems[0])
    ev = fine.evaluate(problem.task_z(problem.initial_point(study.initial_lengths), 0))
    machine = fine.model.machine_at(ev.lengths)
    force = np.asarray(fine.tcp_force, dtype=float)[..., :2]
    out = make_machine_dynamics(machine, None, "newton_euler")(
        ev.joints.position, ev.joints.velocity, ev.joints.acceleration, tcp_force=force
    )
    loads = machine_pin_loads(machine, ev.joints.position, out.pins)
    magnitude = np.asarray(loads.magnitude)
    hinges = set(machine.joint_names)
    return {
        pin.name: ("hinge" if pin.name in hinges else "pin", float(magnitude[:, k].mean()))
        for k, pin in enumerate(loads.pins)
    }


def test_the_excavators_friction_is_mu_r_f_of_its_most_loaded_hinge_and_pin(
    pin_means: dict[str, tuple[str, float]],
) -> None:
    """Coulomb torques = 0.1 x 20 mm x the mean load of the most loaded hinge and actuator pin (file's 0.1 N m)."""
    friction = machine_plant("realistic", load_machine("exact").realistic_plant).joint_friction
    for kind, coulomb in (("hinge", friction.hinge_coulomb_N_m), ("pin", friction.pin_coulomb_N_m)):
        largest = max(load for k, load in pin_means.values() if k == kind)
        assert coulomb == pytest.approx(FRICTION_COEFFICIENT * PIN_RADIUS_M * largest, abs=0.05), kind
    # the viscous terms: 10 % of the Coulomb torque at 0.3 rad/s
    assert friction.hinge_viscous_N_m_s_per_rad == pytest.approx(0.1 * friction.hinge_coulomb_N_m / 0.3, abs=0.05)
    assert friction.pin_viscous_N_m_s_per_rad == pytest.approx(0.1 * friction.pin_coulomb_N_m / 0.3, abs=0.05)

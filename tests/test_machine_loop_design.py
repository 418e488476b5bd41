"""The machine closed loop's velocity-loop bandwidth against the machine's lowest natural frequency (excavator)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from hiab_sim.cli.simulate_summary import bandwidth_line
from hiab_sim.control.cascade import DESIGN_RATIO
from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.env.machine_loop_design import machine_loop_design
from hiab_sim.env.machine_plan import MachinePlan
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.results.read import read_result
from hiab_sim.structure.machine_modes import machine_natural_frequencies

#: Every compliance of the drive trains (screw, nut, bearing, pins) times this: k / 4, f_1 about / 2.
SOFTER = 4.0


def _softer(emlas: EmlaSet, factor: float) -> EmlaSet:
    """Every actuator's drive train ``factor`` times as compliant: E of the screw and each stiffness / factor."""
    named = {}
    for p in emlas:
        assert p.screw is not None and p.stiffness is not None
        stiffness = replace(
            p.stiffness,
            nut_stiffness=p.stiffness.nut_stiffness / factor,
            bearing_stiffness=p.stiffness.bearing_stiffness / factor,
            pin_stiffness=p.stiffness.pin_stiffness / factor,
        )
        named[p.name] = replace(
            p, screw=replace(p.screw, elastic_modulus=p.screw.elastic_modulus / factor), stiffness=stiffness
        )
    return emlas.replaced(**named)


def test_the_check_uses_the_machines_lowest_frequency_over_the_motion(
    excavator_result: Path, excavator_plan: MachinePlan
) -> None:
    """f_1 of the check = the result's own on-path frequency = the MuJoCo path's modes; designed gains pass."""
    plan = excavator_plan
    load_mass = np.zeros((len(plan.time), len(plan.actuator_names)))
    design = machine_loop_design(plan, load_mass)
    check = design.check()
    f_1 = check["first_natural_frequency_Hz"]
    assert isinstance(f_1, float)
    structure = read_result(excavator_result).structure
    assert structure is not None and structure.optimal.lowest_frequency_trajectory_Hz is not None
    assert f_1 == pytest.approx(structure.optimal.lowest_frequency_trajectory_Hz, rel=1e-12)
    mujoco = make_machine_dynamics(plan.machine, None, "mujoco")
    modes = machine_natural_frequencies(
        plan.machine, mujoco, plan.emlas, plan.position, plan.tcp_force[:, :2], plan.payload_kg, tracked=plan.tracked
    )
    assert f_1 == pytest.approx(float(np.min(modes.lowest_Hz)), rel=1e-9)
    assert check["velocity_loop_bandwidth_Hz"] == pytest.approx(min(8.0, DESIGN_RATIO * f_1), rel=1e-12)
    assert check["bandwidth_ratio"] == pytest.approx(DESIGN_RATIO, rel=1e-12)
    assert check["bandwidth_margin"] == pytest.approx(0.1, abs=1e-12)
    assert "holds" in bandwidth_line("optimal", check)


def test_a_softer_drive_train_fails_the_check_of_gains_designed_for_the_stiff_one(excavator_plan: MachinePlan) -> None:
    """A drive stiffness k / 4 halves f_1 (omega^2 = k / m); the stiff train's gains then fail, and one line says so."""
    load_mass = np.zeros((len(excavator_plan.time), len(excavator_plan.actuator_names)))
    stiff = machine_loop_design(excavator_plan, load_mass)
    soft_plan = replace(excavator_plan, emlas=_softer(excavator_plan.emlas, SOFTER))
    soft = machine_loop_design(soft_plan, load_mass, gains=stiff.gains)
    f_stiff, f_soft = stiff.first_natural_frequency_Hz, soft.first_natural_frequency_Hz
    assert f_stiff is not None and f_soft is not None
    assert f_soft == pytest.approx(f_stiff / np.sqrt(SOFTER), rel=0.01)  # the load's geometric stiffness aside
    check = soft.check()
    margin = check["bandwidth_margin"]
    assert isinstance(margin, float) and margin < 0.0
    assert margin == pytest.approx(1.0 - DESIGN_RATIO * f_stiff / (f_soft / 3.0), rel=1e-12)
    line = bandwidth_line("optimal", check)
    assert "\n" not in line and "FAILS" in line and f"{f_soft:.2f} Hz" in line
    # designed for the soft train, the loop slows down with it and passes
    assert machine_loop_design(soft_plan, load_mass).check()["bandwidth_margin"] == pytest.approx(0.1, abs=1e-12)

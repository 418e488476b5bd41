"""``hiab-sim machine import``: an MJCF with slide actuators and connect loops becomes a machine file with the same forces."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from hiab_sim.cli import main
from hiab_sim.machine.assembly import check_machine
from hiab_sim.machine.dynamics_mujoco import MujocoMachineDynamics
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine.mjcf_build import build_machine_spec
from hiab_sim.machine.mjcf_import import import_mjcf
from hiab_sim.machine.mjcf_import_check import fit_ranges, round_trip

TOLERANCE = 1e-9


def exported_mjcf(name: str, folder: Path) -> Path:
    """The branch's own MJCF of a shipped machine, with its ranges and a loop-consistent keyframe added.

    ``mjcf_build`` writes neither joint ranges nor slide ranges (strokes) nor a closed pose; a
    user's file carries them, so they are added here from the machine file.
    """
    machine = load_machine(name)
    spec = build_machine_spec(machine)
    for link in machine.links[1:]:
        joint = spec.joint(link.joint)
        joint.range = list(link.joint_range)
        joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
    for chain in machine.chains:
        if chain.kind != "direct":
            joint = spec.joint(f"{chain.name}.stroke")
            joint.range = [0.0, chain.actuator.stroke]
            joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
    middle = np.array([[0.5 * sum(machine.joint_link(j).joint_range) for j in machine.joint_names]])
    qpos, _, _ = MujocoMachineDynamics(machine).state(middle, np.zeros_like(middle), np.zeros_like(middle))
    spec.compile()
    key = spec.add_key()
    key.name = "home"
    key.qpos = list(qpos[0])
    path = folder / f"{name}.xml"
    path.write_text(spec.to_xml())
    return path


@pytest.mark.parametrize("name", ["xs031", "exact"])
def test_importing_the_exporters_mjcf_reproduces_its_actuator_forces_on_both_paths(name: str, tmp_path: Path) -> None:
    """The shipped machines' MJCF (mjcf_build) imports to a machine whose forces match the MJCF's to 1e-9, and it checks."""
    imported = import_mjcf(exported_mjcf(name, tmp_path))
    machine = fit_ranges(imported)
    assert check_machine(machine) == []
    errors = round_trip(imported, machine, samples=12)
    assert set(errors) == {"newton_euler", "mujoco"}
    assert max(errors.values()) < TOLERANCE
    original = load_machine(name)
    assert machine.actuator_names == original.actuator_names
    assert [c.kind for c in machine.chains] == [c.kind for c in original.chains]
    for mine, theirs in zip(machine.chains, original.chains, strict=True):
        if theirs.kind != "direct":
            assert mine.actuator.retracted_length == pytest.approx(theirs.actuator.retracted_length, abs=1e-6)
            assert mine.actuator.rod_length == pytest.approx(theirs.actuator.rod_length, abs=1e-6)
        assert mine.actuator.stroke == pytest.approx(theirs.actuator.stroke, abs=1e-9)

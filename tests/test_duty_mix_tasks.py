"""The shipped loading cycle and the duty-mix tasks: regenerable, reachable, carriable by the EMLAs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from script_helper import load_script

from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla import ACTUATOR_NAMES, envelope_margins, load_emla_set
from hiab_sim.study.machines.crane_model import CraneModel
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.motion.workspace import initial_joints
from hiab_sim.study.references.kinds import reference_from_mapping
from hiab_sim.study.spec.payload import Payload
from hiab_sim.study.spec.tasks import column_names

OPTIMIZE = Path(__file__).resolve().parents[1] / "optimize"
MIX = yaml.safe_load((OPTIMIZE / "xs031_duty_mix.yaml").read_text())
CRANE = load_crane("xs031")
KIN = tr.TcpKinematics(CRANE)


def test_shipped_loading_cycle_is_what_its_script_writes() -> None:
    """optimize/xs031_loading_cycle.csv is exactly the output of optimize/make_loading_cycle.py."""
    module = load_script("make_loading_cycle", OPTIMIZE / "make_loading_cycle.py")
    assert module.render(KIN) == (OPTIMIZE / "xs031_loading_cycle.csv").read_text(encoding="utf-8")


@pytest.mark.parametrize("index", range(len(MIX["tasks"])), ids=[t["name"] for t in MIX["tasks"]])
def test_duty_mix_task_is_reachable_and_within_the_emla_envelope_with_its_payload(index: int) -> None:
    """Each duty-mix task is reachable, within the joint-rate bounds and EMLA margins >= 0.2 at the built crane."""
    task = MIX["tasks"][index]
    where = f"tasks[{index}]"
    reference = reference_from_mapping(
        task["reference"], f"{where}.reference", OPTIMIZE, MIX["grid"]["duration"], column_names(CraneModel(CRANE))
    )
    payload = Payload.from_value(task["payload"], f"{where}.payload")
    reference.check_reach(KIN, CRANE)
    t = np.linspace(0.0, reference.duration, int(reference.duration / 0.05) + 1)
    ref = reference.sample(KIN, t)
    ik = tr.inverse_kinematics(KIN, ref, tuple(initial_joints(CRANE, ref)[:2]))
    assert np.all(np.abs(ik.velocity).max(axis=0) <= MIX["bounds"]["joint_velocity"])
    force = payload.tcp_force(t, ref.acceleration[:, :2], CRANE.gravity)
    joints = JointSamples(ik.position, ik.velocity, ik.acceleration)
    out = analytic_inverse_dynamics(CRANE, CRANE.default_lengths, joints, tcp_force=force)
    for i, (name, emla) in enumerate(zip(ACTUATOR_NAMES, load_emla_set(None), strict=True)):
        margins = envelope_margins(emla, out.force[:, i], out.velocity[:, i], out.acceleration[:, i])
        assert margins.min() >= 0.2, name

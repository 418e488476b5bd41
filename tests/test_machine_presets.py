"""The shipped machine files: the excavator's geometry against its source, assembly of both, the excavator's EMLA."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest
import yaml

from hiab_sim.emla.config import EmlaParams, emla_set_from_mapping
from hiab_sim.emla.pmsm import dq_voltages
from hiab_sim.machine.kinematics import closure
from hiab_sim.machine.kinematics.assembly import check_machine, usable_stroke
from hiab_sim.machine.loader import PRESETS, load_machine

#: The source's check angles and its polynomial-fit actuator lengths (shared/reference/exact-excavator-arm.yaml).
SOURCE_CHECKS = {
    "boom": ([-0.4737, 0.0, 1.0923], [0.90501, 1.04205, 1.30500]),
    "arm": ([-2.5848, -1.5, -0.5103], [1.55600, 1.30271, 1.04600]),
    "bucket": ([-2.8659, -1.0, 0.0, 0.7839], [1.26000, 1.11147, 0.94316, 0.84000]),
}
#: Published motor torque envelopes [N m] as polynomials of the motor speed [rad/s] (eXactMPC).
PEAK = [4.0269e-9, -3.7090e-6, 8.513e-4, -0.05787, 60.2614]
S1 = [-1.4073e-7, 1.7961e-5, -0.0147, 19.9091]
SPEED_LIMIT = 235.62  # rad/s


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_shipped_machines_assemble_over_their_working_ranges(name: str) -> None:
    """Both presets pass every assembly check (closure, toggle, stroke), also at the middle of their design bounds."""
    machine = load_machine(name)
    assert check_machine(machine) == []
    low, high = machine.design_bounds()
    assert np.all(low <= machine.design_values()) and np.all(machine.design_values() <= high)


def test_excavator_pin_lengths_match_the_source_fits() -> None:
    """The pin-to-pin lengths from the published pivots match the source's own fits at its check angles (< 5e-6 m)."""
    machine = load_machine("exact")
    for name, (angles, lengths) in SOURCE_CHECKS.items():
        chain = machine.chain(name)
        s = closure.closure(machine, chain, np.array(angles)).length
        np.testing.assert_allclose(s, lengths, rtol=0, atol=5e-6)


def test_excavator_strokes_cover_the_joint_limits_with_the_stated_margins() -> None:
    """Each retracted length is 5-6 mm below the shortest length the joint limits need; the longest has >= 5 mm."""
    machine = load_machine("exact")
    for chain in machine.chains:
        low, high = machine.joint_link(chain.joint).joint_range  # type: ignore[misc]
        s = closure.closure(machine, chain, np.linspace(low, high, 2001)).length
        x0 = chain.actuator.retracted_length
        assert x0 is not None
        assert 0.005 <= s.min() - x0 < 0.006
        assert x0 + usable_stroke(chain)[1] - s.max() >= 0.005
        assert chain.actuator.rod_length == pytest.approx(chain.actuator.stroke + 0.155)


def _excavator_emla() -> dict[str, EmlaParams]:
    """The excavator's EMLA file through today's EMLA loader (which names the three actuators lift, tilt, telescope)."""
    text = (resources.files("hiab_sim") / "presets" / "emla_exact.yaml").read_text(encoding="utf-8")
    data = yaml.safe_load(text)
    names = ("boom", "arm", "bucket")
    data["actuators"] = {
        old: data["actuators"][new] for old, new in zip(("lift", "tilt", "telescope"), names, strict=True)
    }
    emla = emla_set_from_mapping(data, "emla_exact.yaml")
    return dict(zip(names, (emla.lift, emla.tilt, emla.telescope), strict=True))


def _torque_limit(params: EmlaParams, speed: np.ndarray) -> np.ndarray:
    """Largest motor torque at each speed within the peak torque and the inverter voltage (i_d = 0)."""
    motor = params.motor
    kt = 1.5 * motor.pole_pairs * motor.flux_linkage
    low, high = np.zeros_like(speed), np.full_like(speed, motor.peak_torque)
    for _ in range(60):  # bisection on the voltage limit of dq_voltages
        mid = 0.5 * (low + high)
        v_d, v_q = dq_voltages(motor, 0.0, mid / kt, speed)
        ok = 1.5 * (v_d**2 + v_q**2) <= motor.max_line_voltage_rms**2
        low, high = np.where(ok, mid, low), np.where(ok, high, mid)
    return low


def test_excavator_emla_matches_the_published_envelopes() -> None:
    """The chosen PMSM follows the published peak curve (4 % over the range, 3 % below 2100 rpm) and its S1 limit."""
    for params in _excavator_emla().values():
        assert 2 * np.pi * params.gear_ratio / params.screw_lead == pytest.approx(2444.16, rel=1e-6)
        assert params.motor.rated_speed == pytest.approx(SPEED_LIMIT, rel=1e-4)
        speed = np.linspace(0.0, SPEED_LIMIT, 400)
        ratio = _torque_limit(params, speed) / np.polyval(PEAK, speed)
        assert np.max(np.abs(ratio - 1.0)) < 0.04
        slow = speed < 2100 * 2 * np.pi / 60
        assert np.max(np.abs(ratio[slow] - 1.0)) < 0.03
        assert ratio[-1] == pytest.approx(1.0, abs=1e-3)  # the voltage limit meets the curve at the speed limit
        s1 = np.polyval(S1, speed)
        assert params.thermal is not None
        assert params.thermal.continuous_torque <= s1.min() + 1e-3
        assert params.thermal.continuous_torque == pytest.approx(s1[-1], abs=2e-3)

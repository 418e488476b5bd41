"""``hiab-sim validate --machine``: Newton-Euler vs MuJoCo and the power balance on any machine file."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hiab_sim.cli import main
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.dynamics.newton_euler import NewtonEulerInverseDynamics
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine_validation import energy_rate, random_machine_states, tcp_velocity


@pytest.mark.parametrize("name", ["exact", "xs031"])
def test_validate_machine_passes_and_writes_the_table(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Both paths agree to round-off and balance the power on both shipped machines: exit 0, table and JSON."""
    status = main(["validate", "--machine", name, "--samples", "12", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert status == 0, out
    assert "| random_states+tcp_force | 12 | (0, -2452) |" in out and "validation passed" in out
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["passed"] is True
    for case in report["cases"]:
        assert max(case["force_rel_error"]) < 1e-9
        assert case["balance_newton_euler"] < 1e-8 and case["balance_mujoco"] < 1e-8
    assert (tmp_path / "table.md").read_text().startswith("Machine: ")


def test_power_balance_detects_a_wrong_tcp_force() -> None:
    """The balance is a real check: the excavator's power with the TCP force of the wrong sign misses dE/dt."""
    machine = load_machine("exact")
    q, dq, ddq = random_machine_states(machine, np.random.default_rng(3), 8)
    force = np.array([300.0, -2000.0])
    out = NewtonEulerInverseDynamics(machine)(q, dq, ddq, force)
    rate = energy_rate(MujocoMachineDynamics(machine), q, dq, ddq)
    v_tcp = tcp_velocity(machine, q, dq, ddq)
    actuators = np.sum(out.force * out.velocity, axis=1)
    scale = np.max(np.abs(actuators + v_tcp @ force))
    assert np.max(np.abs(actuators + v_tcp @ force - rate)) < 1e-9 * scale
    assert np.max(np.abs(actuators - v_tcp @ force - rate)) > 1e-2 * scale


def test_at_rest_the_energy_does_not_change() -> None:
    """dE/dt is zero at rest (dq = ddq = 0) whatever the pose: the stencil sees no motion."""
    machine = load_machine("xs031")
    q, _, _ = random_machine_states(machine, np.random.default_rng(1), 5)
    rate = energy_rate(MujocoMachineDynamics(machine), q, np.zeros_like(q), np.zeros_like(q))
    assert np.max(np.abs(rate)) < 1e-9


def test_validate_machine_exits_1_over_tolerance(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Tolerances below round-off make the same run fail: exit 1 and FAILED naming the cases."""
    cases = tmp_path / "cases.yaml"
    cases.write_text(
        "tolerances: {force_relative: 1.0e-30, velocity_absolute: 1.0e-30, balance_relative: 1.0e-30}\ncases: []\n"
    )
    status = main(["validate", "--machine", "exact", "--cases", str(cases), "--samples", "6", "--out", str(tmp_path)])
    assert status == 1
    assert "validation FAILED: random_states, random_states+tcp_force" in capsys.readouterr().out


@pytest.mark.parametrize("value", ["1", "1,x", "1,nan"])
def test_validate_machine_refuses_a_bad_tcp_force(
    value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A malformed ``--tcp-force`` exits 2 with one line."""
    assert main(["validate", "--machine", "exact", "--tcp-force", value, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--tcp-force" in err


def test_validate_refuses_a_crane_file_beside_a_machine(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--crane FILE beside --machine: one line naming --crane, exit 2, nothing written (it was silently ignored)."""
    out = tmp_path / "v"
    assert main(["validate", "--machine", "exact", "--crane", "xs031", "--samples", "4", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--crane" in err and not out.exists()

"""A machine written from scratch (three booms, a prismatic extension, a jib four-bar) checks and draws."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from hiab_sim.cli import main
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine.loader import load_machine


def _part(mass: float, com: list[float], izz: float) -> dict[str, Any]:
    return {"part": {"mass": mass, "com": com, "inertia_zz": izz}}


def _actuator(stroke: float, piston_offset: float, rod_length: float, emla: str) -> dict[str, Any]:
    return {"stroke": stroke, "piston_offset": piston_offset, "rod_length": rod_length, "emla": emla}


def three_boom_crane_with_jib() -> dict[str, Any]:
    """Column, inner boom, outer boom, telescopic extension and a jib; names unlike either shipped machine."""
    return {
        "name": "three-boom crane with jib",
        "source": "written in tests/test_machine_scratch.py",
        "gravity": 9.81,
        "links": {
            "column": {"bodies": _part(200.0, [0.0, 1.0], 40.0)},
            "inner": {
                "parent": "column",
                "joint": "q_inner",
                "kind": "revolute",
                "joint_frame": {"r": [0.0, 2.0]},
                "joint_range": [-0.2, 1.0],
                "bodies": _part(120.0, [1.5, 0.0], 90.0),
            },
            "outer": {
                "parent": "inner",
                "joint": "q_outer",
                "kind": "revolute",
                "joint_frame": {"r": [3.0, 0.0]},
                "joint_range": [-2.2, -0.4],
                "bodies": _part(80.0, [1.2, 0.0], 40.0),
            },
            "extension": {
                "parent": "outer",
                "joint": "q_ext",
                "kind": "prismatic",
                "joint_frame": {"r": [0.5, 0.0]},
                "joint_range": [0.0, 1.5],
                "bodies": _part(40.0, [1.2, 0.0], 15.0),
            },
            "jib": {
                "parent": "extension",
                "joint": "q_jib",
                "kind": "revolute",
                "joint_frame": {"r": [2.5, 0.0]},
                "joint_range": [-1.5, 0.6],
                "bodies": _part(30.0, [0.8, 0.0], 5.0),
            },
        },
        "chains": {
            "c_inner": {
                "kind": "triangle",
                "joint": "q_inner",
                "pivots": {
                    "base": {"link": "column", "position": [0.3, 0.7]},
                    "end": {"link": "inner", "position": [0.9, -0.2]},
                },
                "actuator": _actuator(0.93, 0.1, 0.96, "m1"),
                "variables": {
                    "L": {"kind": "hinge_distance", "pivot": "base", "bounds": [1.2, 1.5]},
                    "Lc0": {"kind": "piston_offset", "bounds": [0.05, 0.2]},
                    "Lc": {"kind": "rod_length", "bounds": [0.94, 1.1]},
                },
            },
            "c_outer": {
                "kind": "triangle",
                "joint": "q_outer",
                "pivots": {
                    "base": {"link": "inner", "position": [2.0, 0.35]},
                    "end": {"link": "outer", "position": [-0.3, 0.25]},
                },
                "actuator": _actuator(0.6, 0.1, 0.71, "m2"),
            },
            "c_ext": {"kind": "direct", "joint": "q_ext", "actuator": {"stroke": 1.6, "emla": "m3"}},
            "c_jib": {
                "kind": "linkage",
                "joint": "q_jib",
                "pivots": {
                    "base": {"link": "extension", "position": [1.316, 0.32]},
                    "rocker": {"link": "extension", "position": [2.33, 0.0]},
                    "coupler": {"link": "jib", "position": [-0.014, 0.164]},
                },
                "linkage": {"rocker_length": 0.24, "coupler_length": 0.24, "pin_side": 1},
                "actuator": _actuator(0.33, 0.1, 0.75, "m4"),
                "variables": {
                    "gx": {"kind": "pivot_x", "pivot": "base", "bounds": [1.2, 1.4]},
                    "x0": {"kind": "retracted_length", "bounds": [0.8, 0.9]},
                },
            },
        },
        "tcp": {"link": "jib", "r": [1.8, 0.0]},
    }


@pytest.fixture
def crane_file(tmp_path: Path) -> Path:
    """The machine written to a YAML file."""
    path = tmp_path / "three_boom.yaml"
    path.write_text(yaml.safe_dump(three_boom_crane_with_jib(), sort_keys=False), encoding="utf-8")
    return path


def test_machine_check_passes_on_a_machine_written_from_scratch(
    crane_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Check assembles all four chains (two triangles, a direct extension, a jib four-bar): exit 0."""
    assert main(["machine", "check", str(crane_file)]) == 0
    assert "4 chains" in capsys.readouterr().out


def test_machine_show_draws_the_scratch_machine(crane_file: Path, tmp_path: Path) -> None:
    """Show writes the drawing of the scratch machine."""
    figure = tmp_path / "three_boom.png"
    assert main(["machine", "show", str(crane_file), "--figure", str(figure)]) == 0
    assert figure.read_bytes()[:4] == b"\x89PNG"


def test_scratch_tcp_follows_the_hand_written_chain_of_vectors(crane_file: Path) -> None:
    """TCP = (0, 2) + 3 u(q1) + (3 + e) u(q1 + q2) + 1.8 u(q1 + q2 + q4), u(a) = (cos a, sin a), at random states."""
    machine = load_machine(crane_file)
    assert machine.joint_names == ["q_inner", "q_outer", "q_ext", "q_jib"]
    assert machine.variable_keys == ["c_inner.L", "c_inner.Lc0", "c_inner.Lc", "c_jib.gx", "c_jib.x0"]
    rng = np.random.default_rng(2)
    q = rng.uniform(-2.0, 2.0, (100, 4))

    def u(a: np.ndarray) -> np.ndarray:
        return np.stack([np.cos(a), np.sin(a)], axis=-1)

    a1, a2, a4 = q[:, 0], q[:, 0] + q[:, 1], q[:, 0] + q[:, 1] + q[:, 3]
    want = np.array([0.0, 2.0]) + 3.0 * u(a1) + (3.0 + q[:, 2])[:, None] * u(a2) + 1.8 * u(a4)
    np.testing.assert_allclose(forward_kinematics(machine, q).tcp_position[:, :2], want, rtol=0, atol=1e-13)


def test_scratch_machine_with_a_too_short_jib_stroke_fails_check(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Shortening the jib actuator's stroke below what its range needs makes check fail on that line alone."""
    data = three_boom_crane_with_jib()
    data["chains"]["c_jib"]["actuator"]["stroke"] = 0.25
    path = tmp_path / "short.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    assert main(["machine", "check", str(path)]) == 2
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 1 and out[0].startswith("FAIL chains.c_jib.actuator.stroke")

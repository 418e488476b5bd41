"""A machine written from scratch (three booms, a prismatic extension, a jib four-bar) checks, draws and runs.

``optimize``, ``simulate --no-video`` and ``render`` run on it end to end, every name the file's.
"""

from __future__ import annotations

import csv
import itertools
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import hiab_sim
from hiab_sim.cli import main
from hiab_sim.cli.simulate import ENERGY_TOLERANCE, TCP_MAX_MM
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine.loader import load_machine


def _part(mass: float, com: list[float], izz: float) -> dict[str, Any]:
    return {"part": {"mass": mass, "com": com, "inertia_zz": izz}}


def _moving(
    parent: str, joint: str, kind: str, r: list[float], joint_range: list[float], bodies: dict[str, Any]
) -> dict[str, Any]:
    """A moving link: its parent, joint (name, kind, frame offset [m], range) and bodies."""
    return {
        "parent": parent,
        "joint": joint,
        "kind": kind,
        "joint_frame": {"r": r},
        "joint_range": joint_range,
        "bodies": bodies,
    }


def _tube(mass: float, radius: float, length: float) -> dict[str, Any]:
    """A uniform cylinder along x from its pin: com at l/2, I_xx = m r^2/2, I_yy = I_zz = m (3 r^2 + l^2)/12."""
    i_xx, i_yy = mass * radius**2 / 2.0, mass * (3.0 * radius**2 + length**2) / 12.0
    return {
        "mass": mass,
        "com": [length / 2.0, 0.0, 0.0],
        "inertia": [[i_xx, 0.0, 0.0], [0.0, i_yy, 0.0], [0.0, 0.0, i_yy]],
    }


def _actuator(stroke: float, piston_offset: float, rod_length: float, emla: str) -> dict[str, Any]:
    """An EMLA between two pins: a 20 kg housing over Lc0 + stroke and a 4 kg rod over Lc (choices)."""
    return {
        "stroke": stroke,
        "piston_offset": piston_offset,
        "rod_length": rod_length,
        "emla": emla,
        "cylinder_body": _tube(20.0, 0.05, piston_offset + stroke),
        "rod_body": _tube(4.0, 0.02, rod_length),
    }


def three_boom_crane_with_jib() -> dict[str, Any]:
    """Column, inner boom, outer boom, telescopic extension and a jib; names unlike either shipped machine."""
    return {
        "name": "three-boom crane with jib",
        "source": "written in tests/test_machine_scratch.py",
        "gravity": 9.81,
        "links": {
            "column": {"bodies": _part(200.0, [0.0, 1.0], 40.0)},
            "inner": _moving("column", "q_inner", "revolute", [0.0, 2.0], [-0.2, 1.0], _part(120.0, [1.5, 0.0], 90.0)),
            "outer": _moving("inner", "q_outer", "revolute", [3.0, 0.0], [-2.2, -0.4], _part(80.0, [1.2, 0.0], 40.0)),
            "extension": _moving("outer", "q_ext", "prismatic", [0.5, 0.0], [0.0, 1.5], _part(40.0, [1.2, 0.0], 15.0)),
            "jib": _moving("extension", "q_jib", "revolute", [2.5, 0.0], [-1.5, 0.6], _part(30.0, [0.8, 0.0], 5.0)),
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
                "linkage": {
                    "rocker_length": 0.24,
                    "coupler_length": 0.24,
                    "pin_side": 1,
                    # uniform 3 kg bars, I_zz = m l^2 / 12
                    "rocker_body": {"mass": 3.0, "com": [0.12, 0.0], "inertia_zz": 0.0144},
                    "coupler_body": {"mass": 3.0, "com": [0.12, 0.0], "inertia_zz": 0.0144},
                },
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


#: The scratch machine's EMLAs: the eXact excavator's (hiab_sim/presets/emla_exact.yaml), the boom's for the inner
#: boom, the arm's for the outer boom and the extension, the bucket's for the jib (choice: a shipped, cited set).
EMLA_OF = {"m1": "boom", "m2": "arm", "m3": "arm", "m4": "bucket"}
#: A 4 s rest-to-rest quintic move of the four joints [rad, rad, m, rad]: every rod below the EMLAs' 0.0964 m/s.
MOVE_START, MOVE_END, MOVE_DURATION = [0.3, -1.2, 0.5, -0.5], [0.5, -1.0, 0.6, -0.2], 4.0
#: The study: the extension prescribed, the jib's attitude tracked, 20 kg at the TCP; few control points.
SCRATCH_STUDY = {
    "name": "three_boom_move",
    "machine": "three_boom.yaml",
    "emla": "emla_four.yaml",
    "tracked": ["q_ext", "tcp_angle"],
    "tasks": [{"name": "move", "weight": 1, "reference": {"kind": "csv", "file": "move.csv"}, "payload": 20.0}],
    "spline": {"control_points": 10, "degree": 5},
    "grid": {"duration": MOVE_DURATION, "intervals": 10, "fine_factor": 4},
    "bounds": {"joint_velocity": [0.6, 0.6, 0.5, 1.0]},
}


def _joint_move(path: Path, names: list[str]) -> None:
    """The rest-to-rest move as a joint-form trajectory file, 10 Hz."""
    t = np.linspace(0.0, MOVE_DURATION, 41)
    tau = t / MOVE_DURATION
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    q = np.asarray(MOVE_START) + s[:, None] * (np.asarray(MOVE_END) - np.asarray(MOVE_START))
    rows = [",".join(["t", *names])] + [",".join(f"{v:.12g}" for v in row) for row in np.column_stack([t, q])]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")


@pytest.fixture(scope="module")
def scratch_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The scratch machine's study optimised by ``hiab-sim optimize`` (about 10 s); its result folder."""
    folder = tmp_path_factory.mktemp("scratch_study")
    (folder / "three_boom.yaml").write_text(yaml.safe_dump(three_boom_crane_with_jib(), sort_keys=False))
    emla = yaml.safe_load((Path(hiab_sim.__file__).parent / "presets" / "emla_exact.yaml").read_text())
    emla["actuators"] = {name: emla["actuators"][source] for name, source in EMLA_OF.items()}
    (folder / "emla_four.yaml").write_text(yaml.safe_dump(emla, sort_keys=False))
    _joint_move(folder / "move.csv", load_machine(folder / "three_boom.yaml").joint_names)
    (folder / "study.yaml").write_text(yaml.safe_dump(SCRATCH_STUDY, sort_keys=False))
    run = folder / "run"
    flags = ["--no-video", "--no-figures", "--no-report", "--quiet"]
    assert main(["optimize", str(folder / "study.yaml"), "--out", str(run), *flags]) == 0
    return run


@pytest.mark.e2e
def test_optimize_converges_on_the_scratch_machine_under_its_own_names(scratch_run: Path) -> None:
    """The optimum holds every constraint, also on the fine grid with the other ID path; names are the file's.

    The re-check runs the Newton-Euler path against the study's MuJoCo one: their forces agree to 1e-6 N.
    """
    result = json.loads((scratch_run / "result.json").read_text())
    assert result["solver"]["success"] and result["solver"]["max_violation_scaled"] <= 1e-6
    assert result["optimal"]["lengths"]["names"] == ["c_inner.L", "c_inner.Lc0", "c_inner.Lc", "c_jib.gx", "c_jib.x0"]
    assert list(result["optimal"]["actuators"]) == list(EMLA_OF)
    assert result["recheck"]["id_path"] != result["solver"]["id_path"]
    assert result["recheck"]["max_violation_scaled"] <= 1e-6
    assert result["recheck"]["force_difference_between_paths_N"] < 1e-6


@pytest.mark.e2e
def test_simulate_tracks_the_scratch_plan_with_its_predicted_energy(scratch_run: Path, tmp_path: Path) -> None:
    """Closed loop on four drives: each drive's energy (per-step integral) within 2 % of the plan's quadrature."""
    flags = ["--no-video", "--no-figures", "--quiet", "--out", str(tmp_path)]
    assert main(["simulate", str(scratch_run), *flags]) == 0
    report = json.loads((tmp_path / "simulation.json").read_text())
    for design in ("initial", "optimal"):
        summary = report["designs"][design]
        assert list(summary["actuators"]) == list(EMLA_OF)
        for name, drive in summary["actuators"].items():
            predicted = drive["predicted_net_electrical_energy_J"]
            assert drive["net_electrical_energy_J"] == pytest.approx(predicted, rel=ENERGY_TOLERANCE), (design, name)
        assert summary["tcp_error_mm"]["max"] < TCP_MAX_MM


@pytest.mark.e2e
def test_render_plays_the_scratch_result_back(scratch_run: Path, tmp_path: Path) -> None:
    """A 5 fps video of the 4 s move: one frame per 0.2 s from 0 to 4 s, and the machine moves between them."""
    import mediapy

    video = tmp_path / "playback.mp4"
    assert main(["render", str(scratch_run), "-o", str(video), "--size", "160x120", "--fps", "5"]) == 0
    frames = mediapy.read_video(video)
    assert frames.shape == (21, 120, 160, 3)
    assert np.mean(np.abs(frames[0].astype(float) - frames[-1].astype(float))) > 0.5


@pytest.mark.e2e
def test_compare_names_the_scratch_machines_variables_and_mounted_actuators(scratch_run: Path, tmp_path: Path) -> None:
    """The full table's columns are the file's: its five variables, the peaks of the two EMLAs they move (m1, m4).

    Each peak force in the table is the result's own (kN): read back, not recomputed.
    """
    assert main(["compare", str(scratch_run), "--out", str(tmp_path)]) == 0
    with (tmp_path / "comparison.csv").open() as handle:
        table = list(csv.DictReader(handle))
    header = list(table[0])
    assert [h for h in header if h.endswith("[mm]")] == [
        "c_inner L [mm]", "c_inner Lc0 [mm]", "c_inner Lc [mm]", "c_jib gx [mm]", "c_jib x0 [mm]"
    ]  # fmt: skip
    assert [h for h in header if "peak force" in h] == ["m1 peak force [kN]", "m4 peak force [kN]"]
    result = json.loads((scratch_run / "result.json").read_text())
    for row in table:
        for actuator in ("m1", "m4"):
            peak = result[row["design"]]["actuators"][actuator]["peak_force_N"]
            assert float(row[f"{actuator} peak force [kN]"]) == pytest.approx(peak / 1e3, rel=1e-15)


@pytest.mark.e2e
def test_two_starts_on_the_scratch_machine_agree_or_report_their_distinct_optima(
    scratch_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--starts 2`` on a machine file: a second start inside the file's bounds; the optima partition the starts.

    Inside one distinct optimum every start's Xi is within the tolerance of it; two distinct optima differ by more.
    """
    study = scratch_run.parent / "study.yaml"
    flags = ["--no-video", "--no-figures", "--no-report", "--quiet"]
    assert main(["optimize", str(study), "--starts", "2", "--out", str(tmp_path / "run"), *flags]) == 0
    multistart = json.loads((tmp_path / "run" / "result.json").read_text())["multistart"]
    first, second = (np.array(s["initial_lengths"]["values"]) for s in multistart["starts"])
    machine = load_machine(scratch_run.parent / "three_boom.yaml")
    low, high = (np.array(b) for b in machine.design_bounds())
    assert not np.allclose(first, second) and np.all((low <= second) & (second <= high))
    converged = [s for s in multistart["starts"] if s["success"]]
    assert multistart["converged_starts"] == len(converged) == 2
    assert sorted(k for d in multistart["distinct_optima"] for k in d["starts"]) == [0, 1]
    optimum = {s["start"]: np.array(s["optimal_lengths"]["values"]) for s in converged}
    tolerance = multistart["tolerance_m"]
    for d in multistart["distinct_optima"]:
        assert all(np.max(np.abs(optimum[k] - np.array(d["xi"]))) <= tolerance for k in d["starts"])
    pairs = itertools.combinations(multistart["distinct_optima"], 2)
    assert all(np.max(np.abs(np.array(a["xi"]) - np.array(b["xi"]))) > tolerance for a, b in pairs)
    assert multistart["same_optimum"] == (len(multistart["distinct_optima"]) == 1)
    assert "Starts: 2 of 2 converged" in capsys.readouterr().out

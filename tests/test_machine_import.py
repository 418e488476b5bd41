"""``hiab-sim machine import``: an MJCF with slide actuators and connect loops becomes a machine with its forces."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hiab_sim.cli import main
from hiab_sim.machine.kinematics.assembly import check_machine
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine.mjcf_import.importer import import_mjcf
from hiab_sim.machine.mjcf_import.round_trip import fit_ranges, round_trip
from hiab_sim.machine_mjcf import machine_mjcf

TOLERANCE = 1e-9


def exported_mjcf(name: str, folder: Path) -> Path:
    """The MJCF ``hiab-sim mjcf --machine`` writes for a shipped machine, as written (ranges and keyframe included)."""
    path = folder / f"{name}.xml"
    path.write_text(machine_mjcf(load_machine(name)))
    return path


@pytest.mark.parametrize("name", ["xs031", "exact"])
def test_importing_the_exporters_mjcf_reproduces_its_actuator_forces_on_both_paths(name: str, tmp_path: Path) -> None:
    """The shipped machines' exported MJCF imports, unedited, to a machine with the MJCF's forces to 1e-9; it checks."""
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


def test_importing_the_hiab_sim_mjcf_crane_file_reproduces_its_forces(tmp_path: Path) -> None:
    """``hiab-sim mjcf`` (joints placed by ``ref``, armature, damping, servo actuators) imports to the MJCF's forces."""
    path = tmp_path / "crane.xml"
    assert main(["mjcf", "-o", str(path)]) == 0
    imported = import_mjcf(path)
    machine = fit_ranges(imported)
    assert check_machine(machine) == []
    assert max(round_trip(imported, machine, samples=12).values()) < TOLERANCE


def _rot_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def handmade_mjcf(
    ball: bool = False, extra: str = "", second_slide: bool = False, unlocked: str = "", rigid_ram: bool = False
) -> str:
    """A digger written by hand, not in the exporter's style.

    x-z plane with hinges about +y (so the machine's x is MuJoCo's -x), a slewing column, degree
    euler angles, ``zaxis`` and ``quat`` orientations, default classes and ``childclass``,
    ``fullinertia``, inertia from geoms; the boom cylinder hangs on the boom (the driven link) with
    its rod pinned to the column, the arm cylinder on the boom, a bucket four-bar whose actuator
    ends on the rocker. Body ``connect`` equalities close at qpos0 (MuJoCo places anchor 2 there).
    """
    boom_origin = np.array([0.2, 0.0, 1.0])  # world, column at (0, 0, 0.5) + boom pos
    d_boom = np.array([0.9, 0.0, -0.15])  # cylinder pivot on the boom (boom frame = world axes)
    c_column = np.array([0.1, 0.0, -0.2])  # column pivot, column frame
    boom_d_world = boom_origin + d_boom
    c_world = np.array([0.0, 0.0, 0.5]) + c_column
    boom_dir = c_world - boom_d_world
    arm_rot = _rot_y(np.radians(20.0))  # arm euler="0 20 0" in the boom
    e_boom, f_arm = np.array([1.0, 0.0, 0.3]), np.array([-0.25, 0.0, 0.15])
    f_boom = np.array([2.0, 0.0, 0.0]) + arm_rot @ f_arm
    arm_dir = f_boom - e_boom
    j_arm, h_arm, k_arm = np.array([0.8, 0.0, 0.15]), np.array([0.86, 0.0, 0.33]), np.array([1.1, 0.0, 0.14])
    g_arm = np.array([0.0, 0.0, 0.32])
    bucket_dir = h_arm - g_arm
    coupler_rot = _rot_y(0.4)
    k_in_coupler = coupler_rot.T @ (k_arm - h_arm)

    def z(v: np.ndarray) -> str:
        return " ".join(f"{x:.12g}" for x in v)

    def length(v: np.ndarray) -> float:
        return float(np.linalg.norm(v))

    joint = "ball" if ball else "hinge"
    boom_rod_end = length(boom_dir) - 0.3 - (0.1 if second_slide else 0.0)
    mid = (
        '<body name="mid" pos="0 0 0.1"><joint name="mid_slide" class="ram" range="-0.1 0.1"/>'
        '<inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>'
        if second_slide
        else ""
    )
    return f"""
<mujoco model="handmade digger">
  <compiler angle="degree" autolimits="true" inertiafromgeom="auto"/>
  <option gravity="0 0 -9.81"/>
  <default>
    <default class="pin"><joint type="hinge" axis="0 1 0"/><geom type="capsule" size="0.03" density="2000"/></default>
    <default class="ram"><joint type="slide" axis="0 0 1"/></default>
  </default>
  <worldbody>
    <body name="column" pos="0 0 0.5">
      <joint name="slew" type="hinge" axis="0 0 1" {unlocked}/>
      <inertial pos="0 0 0" mass="200" diaginertia="10 10 5"/>
      <body name="boom" pos="0.2 0 0.5" childclass="pin">
        <joint name="lift" range="-17 17"/>
        <inertial pos="1 0.01 0.1" mass="150" fullinertia="5 60 62 0.5 -1 0.2"/>
        <site name="boom_tip" pos="2 0 0"/>
        <body name="boom_cyl" pos="{z(d_boom)}" zaxis="{z(boom_dir)}">
          <joint name="boom_pin" type="{joint}"/>
          <inertial pos="0 0 0.3" mass="20" diaginertia="0.6 0.6 0.02"/>
          {mid}
          <body name="boom_rod" pos="0 0 0.3">
            <joint name="boom_ram" {'type="hinge" axis="0 1 0"' if rigid_ram else 'class="ram"'} range="-0.25 0.25"/>
            <inertial pos="0 0 0.4" mass="8" diaginertia="0.3 0.3 0.005"/>
          </body>
          {"</body>" if second_slide else ""}
        </body>
        <body name="arm_cyl" pos="{z(e_boom)}" zaxis="{z(arm_dir)}">
          <joint name="arm_pin"/>
          <geom fromto="0 0 0 0 0 0.4"/>
          <body name="arm_rod" pos="0 0 0.3">
            <joint name="arm_ram" class="ram" range="-0.25 0.25"/>
            <geom fromto="0 0 0 0 0 {length(arm_dir) - 0.3:.12g}" size="0.02"/>
          </body>
        </body>
        <body name="arm" pos="2 0 0" euler="0 20 0">
          <joint name="curl" range="-23 23"/>
          <inertial pos="0.4 0 0.05" mass="60" fullinertia="1 8 8.5 0 0.1 0"/>
          <body name="bucket_cyl" pos="{z(g_arm)}" zaxis="{z(bucket_dir)}">
            <joint name="bucket_pin"/>
            <inertial pos="0 0 0.2" mass="10" diaginertia="0.2 0.2 0.01"/>
            <body name="bucket_rod" pos="0 0 0.25">
              <joint name="bucket_ram" class="ram" range="-0.12 0.12"/>
              <inertial pos="0 0 0.2" mass="3" diaginertia="0.05 0.05 0.001"/>
            </body>
          </body>
          <body name="rocker" pos="{z(j_arm)}">
            <joint name="rocker_pin"/>
            <geom fromto="0 0 0 {z(h_arm - j_arm)}"/>
            <body name="coupler" pos="{z(h_arm - j_arm)}" quat="{np.cos(0.2):.15g} 0 {np.sin(0.2):.15g} 0">
              <joint name="coupler_pin"/>
              <geom fromto="0 0 0 {z(k_in_coupler)}"/>
            </body>
          </body>
          <body name="bucket" pos="1 0 0" euler="0 -5 0">
            <joint name="tip_joint" range="-25 25"/>
            <inertial pos="0.25 0 0.1" mass="40" fullinertia="0.8 1.2 1.1 0 0.05 0"/>
            <site name="teeth" pos="0.5 0 0"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <equality>
    <connect name="boom_end" body1="boom_rod" body2="column" anchor="0 0 {boom_rod_end:.12g}"/>
    <connect name="arm_end" body1="arm_rod" body2="arm" anchor="0 0 {length(arm_dir) - 0.3:.12g}"/>
    <connect name="bucket_rod_end" body1="bucket_rod" body2="rocker" anchor="0 0 {length(bucket_dir) - 0.25:.12g}"/>
    <connect name="bucket_link" body1="coupler" body2="bucket" anchor="{z(k_in_coupler)}"/>
  </equality>
  {extra}
  <actuator>
    <motor name="boom" joint="boom_ram"/>
    <motor name="arm" joint="arm_ram"/>
    <motor name="bucket" joint="bucket_ram"/>
  </actuator>
</mujoco>
"""


def test_importing_a_handwritten_mjcf_with_a_locked_slewing_joint_reproduces_its_forces(tmp_path: Path) -> None:
    """Another style (nesting, frames, euler, classes, fullinertia, four-bar, slewing locked): forces to 1e-9."""
    path = tmp_path / "digger.xml"
    path.write_text(handmade_mjcf())
    imported = import_mjcf(path, tcp="teeth", locks={"slew": 0.3})
    machine = fit_ranges(imported)
    assert check_machine(machine) == []
    assert [c.kind for c in machine.chains] == ["triangle", "triangle", "linkage"]
    assert machine.actuator_names == ["boom", "arm", "bucket"]
    assert max(round_trip(imported, machine, samples=12).values()) < TOLERANCE


def _run_import(tmp_path: Path, text: str, *extra: str) -> tuple[int, Path]:
    source = tmp_path / "model.xml"
    source.write_text(text)
    output = tmp_path / "machine.yaml"
    return main(["machine", "import", str(source), "-o", str(output), "--samples", "4", *extra]), output


UNSUPPORTED = {
    "ball joint in a chain": (dict(ball=True), "joint 'boom_pin' (ball)"),
    "tendon": (
        dict(extra='<tendon><fixed name="coupling"><joint joint="lift" coef="1"/></fixed></tendon>'),
        "tendon 'coupling'",
    ),
    "two actuators in one loop": (dict(second_slide=True), "two actuators"),
    "slewing joint not locked": (dict(), "joint 'slew': hinge axis"),
    "loop with no slide": (dict(rigid_ram=True), "equality 'boom_end': closes a loop with no slide joint"),
    "weld equality": (
        dict(extra='<equality><weld name="glue" body1="arm" body2="boom"/></equality>'),
        "equality 'glue' (weld)",
    ),
    "flex": (
        dict(
            extra='<deformable><flex name="sheet" dim="2" body="boom arm bucket" vertex="0 0 0 0 0 0 0 0 0" '
            'element="0 1 2"/></deformable>'
        ),
        "flex 'sheet'",
    ),
}


@pytest.mark.parametrize("case", sorted(UNSUPPORTED))
def test_every_unsupported_construct_exits_2_with_one_line_naming_it_and_writes_nothing(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ball joints, tendons, flexes, two slides in one loop, an unlocked slewing hinge, a slideless loop, welds."""
    kwargs, needle = UNSUPPORTED[case]
    locks = [] if case == "slewing joint not locked" else ["--lock", "slew=0.3"]
    status, output = _run_import(tmp_path, handmade_mjcf(**kwargs), "--tcp", "teeth", *locks)
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2
    assert len(err) == 1 and needle in err[0], err
    assert not output.exists()


def test_an_out_of_plane_hinge_axis_names_the_joint(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A hinge tilted out of the plane is one line naming it (with the lock hint), exit 2."""
    text = handmade_mjcf().replace(
        '<joint name="curl" range="-23 23"/>', '<joint name="curl" axis="0 1 0.3" range="-23 23"/>'
    )
    status, output = _run_import(tmp_path, text, "--tcp", "teeth", "--lock", "slew=0")
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "joint 'curl'" in err[0] and "--lock curl=VALUE" in err[0]
    assert not output.exists()


@pytest.mark.parametrize("text", [None, "<mujoco><worldbody><body></mujoco>"])
def test_a_missing_or_malformed_file_is_one_line_and_writes_nothing(
    text: str | None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No file, or XML MuJoCo cannot compile: one line, exit 2, no output."""
    output = tmp_path / "machine.yaml"
    source = tmp_path / "model.xml"
    if text is not None:
        source.write_text(text)
    assert main(["machine", "import", str(source), "-o", str(output)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "model.xml" in err[0]
    assert not output.exists()


def test_the_import_command_writes_a_commented_file_that_machine_check_passes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The CLI prints the round trip on both paths, writes every value with a comment, and ``machine check`` passes."""
    status, output = _run_import(tmp_path, handmade_mjcf(), "--tcp", "teeth", "--lock", "slew=0.3")
    out = capsys.readouterr().out
    assert status == 0
    values = [float(line.rsplit(" ", 1)[1]) for line in out.splitlines() if line.startswith("round trip")]
    assert len(values) == 2 and max(values) < TOLERANCE
    for line in output.read_text().splitlines():
        body = line.split("#", 1)[0]
        if body.strip() and not body.rstrip().endswith(":") and ": " in body:
            assert "#" in line, line  # every value says where it came from
    assert main(["machine", "check", str(output)]) == 0
    machine = load_machine(output)
    assert {v.key for v in machine.decision_variables} >= {
        "boom.hinge_distance",
        "boom.piston_offset",
        "boom.rod_length",
        "bucket.retracted_length",
    }

"""``hiab-sim machine import`` on a user's own loader crane: the file's names, float noise and mistakes.

The MJCF is written here as a user would write it (two booms, each lifted by a cylinder whose rod a
``connect`` pins to the boom; slide ranges measured from the drawn pose, so their ends carry decimal
noise), not exported by hiab-sim. Each test holds one thing a user met following docs/import.md.
"""

from __future__ import annotations

from pathlib import Path
from string import Template

import numpy as np
import pytest

from hiab_sim.cli import main
from hiab_sim.machine.loader import load_machine
from hiab_sim.study.analysis.buildable import rounded_values

DATA = Path(__file__).parent / "data"


def user_crane(lift: str = "lift", fold: str = "fold", fold_anchor: str = "0.8 0 0", keyframe: str = "") -> str:
    """A loader crane in the x-z plane (hinges about -y, radians): base, boom1 (q1), boom2 (q2), two cylinders.

    The lift cylinder's slide range [-0.16297033, 0.65702967] m gives the stroke 0.8200000000000001 m
    in floating point; ``fold_anchor`` is the fold rod's pin in the rod body [m].
    """
    template = Template((DATA / "user_crane.xml").read_text(encoding="utf-8"))
    return template.substitute(lift=lift, fold=fold, fold_anchor=fold_anchor, keyframe=keyframe)


def _import(tmp_path: Path, text: str, *extra: str) -> tuple[int, Path]:
    source = tmp_path / "crane.xml"
    source.write_text(text)
    output = tmp_path / "crane.yaml"
    return main(["machine", "import", str(source), "-o", str(output), "--samples", "4", *extra]), output


def _refused(tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, *extra: str) -> str:
    """Import ``text``: exit 2, one line and no traceback on stderr, no machine file written; the line."""
    status, output = _import(tmp_path, text, *extra)
    assert status == 2
    line = _one_error(capsys)
    assert not output.exists()
    return line


def _one_error(capsys: pytest.CaptureFixture[str]) -> str:
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, lines
    assert "Traceback" not in captured.err
    return lines[0]


def test_a_design_rounded_at_a_proposed_bound_is_accepted_by_the_bounds_check(tmp_path: Path) -> None:
    """A design rounded to 1 mm at a proposed bound lies inside the bounds: they carry no float noise.

    The lift rod length's lower bound was the stroke 0.8200000000000001 m, so the buildable design 0.82 m that
    ``optimize`` printed as ``mjcf --machine --design`` was refused.
    """
    status, output = _import(tmp_path, user_crane())
    assert status == 0
    machine = load_machine(output)
    low = np.array([v.low for v in machine.decision_variables])
    up = np.array([v.high for v in machine.decision_variables])
    for at_bound in (low, up):
        machine.with_design(rounded_values(at_bound, 1e-3, low, up))  # raises when a rounded value leaves a bound
    assert np.array_equal(low, np.round(low, 9)) and np.array_equal(up, np.round(up, 9))
    assert main(["machine", "check", str(output)]) == 0


def test_actuator_names_that_are_no_identifiers_give_emla_names_an_emla_file_accepts(tmp_path: Path) -> None:
    """MJCF actuators 'Lift-EMLA' and 'Fold EMLA' keep their names as chains; their EMLA names are identifiers."""
    status, output = _import(tmp_path, user_crane(lift="Lift-EMLA", fold="Fold EMLA"))
    assert status == 0
    machine = load_machine(output)
    assert machine.actuator_names == ["Lift-EMLA", "Fold EMLA"]
    assert [c.actuator.emla for c in machine.chains] == ["Lift_EMLA", "Fold_EMLA"]


def test_a_machine_file_whose_emla_name_is_no_identifier_is_one_line_naming_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An EMLA file keys its actuators by identifiers, so ``emla: Lift-EMLA`` is refused where it is written."""
    status, output = _import(tmp_path, user_crane())
    assert status == 0
    edited = tmp_path / "edited.yaml"
    edited.write_text(output.read_text().replace("emla: lift", "emla: Lift-EMLA"))
    capsys.readouterr()
    assert main(["machine", "check", str(edited)]) == 2
    line = _one_error(capsys)
    assert "chains.lift.actuator.emla" in line and "'Lift-EMLA'" in line and "identifier" in line


@pytest.mark.parametrize("samples", ["0", "-5"])
def test_a_sample_count_below_one_is_one_line_and_writes_nothing(
    samples: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--samples 0`` (or negative) names the option, its value and the allowed range; exit 2."""
    line = _refused(tmp_path, capsys, user_crane(), "--samples", samples)
    assert "--samples" in line and samples in line and ">= 1" in line


def test_an_output_that_is_a_folder_or_in_no_folder_is_refused_before_the_import(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o`` naming an existing folder, or a file in a missing folder: one line, nothing printed or written."""
    source = tmp_path / "crane.xml"
    source.write_text(user_crane())
    folder = tmp_path / "out"
    folder.mkdir()
    for output in (folder, tmp_path / "missing" / "crane.yaml"):
        assert main(["machine", "import", str(source), "-o", str(output)]) == 2
        assert capsys.readouterr().out == ""
    assert list(folder.iterdir()) == [] and not (tmp_path / "missing").exists()


def test_writing_onto_an_existing_folder_is_one_line_in_every_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``mjcf -o FOLDER`` and ``machine show --figure FOLDER``: exit 2 and one line, not a traceback."""
    folder = tmp_path / "out"
    folder.mkdir()
    assert main(["mjcf", "--machine", "exact", "-o", str(folder)]) == 2
    assert str(folder) in _one_error(capsys)
    assert main(["machine", "show", "exact", "--figure", str(folder)]) == 2
    capsys.readouterr()  # show prints the machine before it draws
    assert list(folder.iterdir()) == []


def test_a_lock_value_that_is_not_finite_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--lock q1=nan`` names the option and the value, not a chain it broke."""
    line = _refused(tmp_path, capsys, user_crane(), "--lock", "q1=nan")
    assert "--lock" in line and "q1=nan" in line and "finite" in line


def test_a_model_without_connect_equalities_is_one_line_saying_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No ``connect`` closes a loop: one line saying so and naming the undriven hinges, not a cascade of lines."""
    text = user_crane()
    start, end = text.index("<equality>"), text.index("</equality>") + len("</equality>")
    line = _refused(tmp_path, capsys, text[:start] + text[end:])
    assert "connect" in line and "'q1'" in line and "'q2'" in line


def test_a_cylinder_whose_stroke_is_not_shorter_than_its_retracted_length_names_the_slide(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A rod pinned at its body's origin makes x0 = 0.53 m < stroke 0.635 m: one line naming the slide and both.

    It named a proposed ``rod_length`` variable the user never wrote.
    """
    line = _refused(tmp_path, capsys, user_crane(fold_anchor="0 0 0"))
    assert "joint 's2'" in line and "0.53" in line and "0.635" in line
    assert "variables" not in line


def test_a_keyframe_whose_pins_do_not_close_is_named_where_the_reference_pose_is_chosen(tmp_path: Path) -> None:
    """A keyframe whose connect pins do not close is skipped, and the file's header says so with the pins' gap.

    MuJoCo computes a connect's second anchor at qpos0, so a keyframe written for the user's own pin
    positions may not close; the header named only qpos0.
    """
    key = '<keyframe><key name="home" qpos="0.4 -1.2 0.057 0.33 1.22 0.44"/></keyframe>'
    status, output = _import(tmp_path, user_crane(keyframe=key))
    assert status == 0
    header = [line for line in output.read_text().splitlines() if line.startswith("# reference pose")]
    assert len(header) == 1 and "qpos0" in header[0] and "keyframe 'home' skipped" in header[0]


@pytest.mark.e2e
def test_the_imported_crane_optimises_and_the_printed_mjcf_command_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Import, a 4 s TCP move, ``optimize``, then the ``mjcf`` command the summary prints, as printed.

    The summary lists the machine copy that command reads, and the command writes the buildable
    design's MJCF (the lift rod length ends at its bound).
    """
    import yaml

    from hiab_sim.resources import shipped

    assert _import(tmp_path, user_crane())[0] == 0
    emla = yaml.safe_load(shipped("emla", "xs031").read_text())
    emla["actuators"] = {"lift": emla["actuators"]["lift"], "fold": emla["actuators"]["tilt"]}
    (tmp_path / "emla.yaml").write_text(yaml.safe_dump(emla))
    t = np.linspace(0.0, 4.0, 201)
    s = t / 4.0
    blend = 10 * s**3 - 15 * s**4 + 6 * s**5
    start, end = np.array([2.753984, 0.172474]), np.array([3.340563, 1.916326])  # m, q = (0.3, -0.3), (0.7, 0.1)
    rows = [f"{a:.6f},{p[0]:.6f},{p[1]:.6f}" for a, p in zip(t, start + np.outer(blend, end - start), strict=True)]
    (tmp_path / "move.csv").write_text("t,x,y\n" + "\n".join(rows) + "\n")
    (tmp_path / "study.yaml").write_text(
        "name: user_move\nmachine: crane.yaml\nemla: emla.yaml\nspline: {control_points: 12, degree: 5}\n"
        "grid: {duration: 4.0, intervals: 16, fine_factor: 10}\n"
        "tasks: [{name: move, weight: 1, reference: {kind: csv, file: move.csv}}]\n"
        "tracking: {position: 2.0e-3, velocity: 1.0e-2, acceleration: 0.1}\n"
        "bounds: {joint_velocity: [0.6, 0.6], working_range: machine}\nsolver: {id_path: analytic}\n"
    )
    capsys.readouterr()
    run = tmp_path / "run"
    argv = ["optimize", str(tmp_path / "study.yaml"), "--out", str(run), "--no-video", "--no-figures", "--no-report"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "machine.yaml" in out.split("Files in", 1)[1] and (run / "machine.yaml").is_file()
    command = out.split("Model of the buildable design: hiab-sim ", 1)[1].splitlines()[0].split()
    assert "lift.rod_length=0.82" in command
    assert main([*command, "-o", str(tmp_path / "built.xml")]) == 0
    assert (tmp_path / "built.xml").is_file()


def test_radian_ranges_in_a_file_read_in_degrees_are_named_with_what_they_became(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without ``<compiler angle="radian"/>`` MuJoCo reads ``range="-0.2 1.1"`` as degrees: 1.1 deg is 0.0192 rad.

    The import follows MuJoCo (the range it writes is the compiled one) and says so, per hinge, on the
    console and in the file's header, with the range in radians the numbers would have given. The
    same crane with the compiler line gives no such warning.
    """
    assert _import(tmp_path, user_crane())[0] == 0
    assert "warning" not in capsys.readouterr().err
    in_degrees = user_crane().replace('<compiler angle="radian"/>', "").replace('euler="0 1.2 0"', 'euler="0 68.75 0"')
    in_degrees = in_degrees.replace('euler="0 -0.05710043 0"', 'euler="0 -3.27161 0"')
    in_degrees = in_degrees.replace('euler="0 -1.12637712 0"', 'euler="0 -64.5366 0"')
    in_degrees = in_degrees.replace('range="-1.3 1.0"', 'range="-74.48 57.3"')  # q2 written in degrees: no warning
    status, output = _import(tmp_path, in_degrees)
    assert status == 0, capsys.readouterr().err
    warned = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warned) == 1 and "joint 'q1'" in warned[0]
    assert "[-0.003491, 0.0192] rad" in warned[0] and "[-0.2, 1.1] rad" in warned[0]
    assert f"# warning: {warned[0].split('warning: ', 1)[1]}" in output.read_text().splitlines()
    low, up = next(link.joint_range for link in load_machine(output).links if link.joint == "q1")
    assert up - low == pytest.approx(np.radians(1.3), rel=1e-6)  # the compiled range, kept as MuJoCo reads it


def test_joint_damping_and_armature_left_aside_are_named_with_their_values(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A joint's damping and armature are not part of the machine format: the import names them, not drops them."""
    text = user_crane().replace('range="-0.2 1.1"/>', 'range="-0.2 1.1" damping="350" armature="0.4"/>')
    status, output = _import(tmp_path, text)
    assert status == 0
    warned = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warned) == 1
    assert "joint 'q1'" in warned[0] and "damping 350" in warned[0] and "armature 0.4" in warned[0]
    assert "stiffness" not in warned[0] and "left aside" in warned[0]
    assert any(line.startswith("# warning: joint 'q1'") for line in output.read_text().splitlines())

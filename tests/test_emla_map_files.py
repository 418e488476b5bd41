"""``hiab-sim emla-map --emla FILE``: any EMLA file's actuator names."""

from __future__ import annotations

from pathlib import Path

import pytest

from hiab_sim.cli import main


def test_emla_map_draws_an_actuator_of_the_excavator_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--emla exact --actuator arm`` exits 0, writes the PNG and names the arm in its summary."""
    out = tmp_path / "arm.png"
    status = main(["emla-map", "--emla", "exact", "--actuator", "arm", "-o", str(out), "--resolution", "11"])
    assert status == 0
    assert out.stat().st_size > 0
    assert capsys.readouterr().out.startswith("arm: peak force")


def test_emla_map_defaults_to_the_files_first_actuator(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Without ``--actuator`` the map is of the file's first actuator (the excavator's boom)."""
    out = tmp_path / "first.png"
    assert main(["emla-map", "--emla", "exact", "-o", str(out), "--resolution", "11"]) == 0
    assert capsys.readouterr().out.startswith("boom: ")


def test_emla_map_rejects_a_name_the_file_lacks(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An actuator name the file lacks exits 2 with one line naming the file's actuators."""
    status = main(["emla-map", "--emla", "exact", "--actuator", "lift", "-o", str(tmp_path / "x.png")])
    assert status == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err
    assert "boom, arm, bucket" in err and "'lift'" in err
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize(
    ("arguments", "named"),
    [
        (["--resolution", "-5"], "--resolution = -5 is out of range: must be an integer from 3 to 2001"),
        (["--resolution", "2002"], "--resolution = 2002"),
        (["-o", "{tmp}/map.jpg"], "--output = '{tmp}/map.jpg' is out of range: must end with .png"),
        (["--csv", "{tmp}/grid.txt"], "--csv = '{tmp}/grid.txt' is out of range: must end with .csv"),
        (["--npz", "{tmp}/grid"], "--npz = '{tmp}/grid' is out of range: must end with .npz"),
    ],
)
def test_emla_map_refuses_a_bad_option_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], arguments: list[str], named: str
) -> None:
    """A resolution outside 3..2001 or a file without its format's suffix: one line naming the option, no file."""
    given = [a.replace("{tmp}", str(tmp_path)) for a in arguments]
    if "-o" not in given:
        given += ["-o", str(tmp_path / "map.png")]
    assert main(["emla-map", "--emla", "exact", *given]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert named.replace("{tmp}", str(tmp_path)) in err
    assert not list(tmp_path.iterdir())

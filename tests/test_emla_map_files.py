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

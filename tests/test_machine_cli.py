"""``hiab-sim machine show|check``: prints, draws, checks; bad files exit 2 with one line and write nothing."""

from __future__ import annotations

import copy
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
import yaml

from hiab_sim.cli import main

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _excavator() -> dict[str, Any]:
    text = (resources.files("hiab_sim") / "presets" / "exact_excavator.yaml").read_text(encoding="utf-8")
    data = yaml.safe_load(text)
    assert isinstance(data, dict)
    return data


def _write(tmp_path: Path, data: dict[str, Any], name: str = "machine.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


@pytest.mark.parametrize("name", ["xs031", "exact"])
def test_machine_check_passes_on_both_presets(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Both shipped machines assemble over their working ranges: exit 0 and one summary line."""
    assert main(["machine", "check", name]) == 0
    assert "every chain assembles" in capsys.readouterr().out


def test_machine_show_prints_and_writes_a_png(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Show prints links, chains, ranges, masses and decision variables and writes a PNG drawing."""
    figure = tmp_path / "exact.png"
    assert main(["machine", "show", "exact", "--figure", str(figure)]) == 0
    out = capsys.readouterr().out
    for text in ("links:", "chains:", "usable stroke", "reachable", "decision variables:", "bucket.x0", "kg"):
        assert text in out
    assert figure.read_bytes()[:8] == PNG_SIGNATURE
    assert figure.stat().st_size > 20_000


def test_machine_show_names_its_drawing_after_the_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Without --figure: <name>_machine.png, and a file already named ...machine.yaml is not doubled."""
    monkeypatch.chdir(tmp_path)
    source = Path(str(resources.files("hiab_sim") / "presets" / "xs031_machine.yaml"))
    assert main(["machine", "show", "exact"]) == 0
    assert main(["machine", "show", str(source)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["exact_machine.png", "xs031_machine.png"]


def test_machine_check_lists_each_failure_and_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A short stroke, a range through a toggle and a TCP outside the workspace: one FAIL line each, exit 2."""
    data = _excavator()
    data["chains"]["arm"]["actuator"]["stroke"] = 0.45
    data["links"]["boom"]["joint_range"] = [-0.4737, 2.9]
    path = _write(tmp_path, data)
    assert main(["machine", "check", str(path)]) == 2
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("FAIL")]
    assert any("chains.arm.actuator.stroke" in line for line in lines)
    assert any("links.boom.joint_range" in line and "toggle" in line for line in lines)
    data = _excavator()
    data["workspace"] = {"x": [-5.0, 5.0], "y": [-0.95737, 5.0]}  # the ground as a floor: the bucket digs below it
    assert main(["machine", "check", str(_write(tmp_path, data, "floor.yaml"))]) == 2
    out = capsys.readouterr().out
    assert out.count("FAIL") == 1 and "workspace" in out


@pytest.mark.parametrize(
    ("path", "value", "field"),
    [
        ("chains.bucket.pivots.rocker.link", "stick", "chains.bucket.pivots.rocker.link"),
        ("links.bucket.bodies.bucket.inertia_zz", -3.0, "links.bucket.bodies.bucket.inertia_zz"),
        ("chains.boom.actuator.stroke", 0.3, "chains.boom.actuator.stroke"),
        ("links.arm.joint", "alpha", "links.arm.joint"),
        ("chains.bucket.linkage.pin_side", 2, "chains.bucket.linkage.pin_side"),
        ("chains.bucket.linkage.pin_side", True, "chains.bucket.linkage.pin_side"),
        ("links.boom.bodies.boom.mass", 1e300, "links.boom.bodies.boom.mass"),  # overflowed the energy integrals
    ],
)
def test_bad_machine_file_exits_2_with_one_line_and_writes_nothing(
    path: str, value: Any, field: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Show and check on a bad file: exit 2, one stderr line naming the field, no traceback, no PNG."""
    data = copy.deepcopy(_excavator())
    *parents, last = path.split(".")
    node = data
    for key in parents:
        node = node[key]
    node[last] = value
    source = _write(tmp_path, data)
    figure = tmp_path / "out.png"
    assert main(["machine", "show", str(source), "--figure", str(figure)]) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and field in captured.err and "Traceback" not in captured.err
    assert not figure.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["machine.yaml"]
    assert main(["machine", "check", str(source)]) == 2  # check: one line, an error or a FAIL report
    captured = capsys.readouterr()
    report = captured.out + captured.err
    assert report.count("\n") == 1 and field in report

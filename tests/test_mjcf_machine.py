"""``hiab-sim mjcf --machine``: a machine file's generic MJCF, posed on its loops and framed."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from hiab_sim.cli import main
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine_mjcf import home_joints
from hiab_sim.model.mjcf import SOURCE_TO_WORLD


@pytest.mark.parametrize("name", ["exact", "xs031"])
def test_machine_mjcf_home_closes_every_loop_and_matches_the_forward_kinematics(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The written file loads; at ``home`` the connect equalities hold and the TCP is where the description puts it."""
    out = tmp_path / "m.xml"
    assert main(["mjcf", "--machine", name, "-o", str(out)]) == 0
    assert capsys.readouterr().out.startswith(f"wrote {out}: ")
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    assert model.neq > 0 and data.nefc > 0
    assert np.max(np.abs(data.efc_pos)) < 1e-12  # every pin: site a on site b [m]
    machine = load_machine(name)
    frames = forward_kinematics(machine, home_joints(machine))
    tcp = SOURCE_TO_WORLD @ frames.tcp_position  # the description's plane (x, y up) is MuJoCo's x-z
    np.testing.assert_allclose(data.site("tcp").xpos, tcp, atol=1e-12)
    for camera in ("side", "perspective"):
        assert model.camera(camera).id >= 0


def test_machine_mjcf_design_item_moves_the_pivot(tmp_path: Path) -> None:
    """``--design boom.L=...`` builds that design: the model differs from the file's design and still closes."""
    base, moved = tmp_path / "a.xml", tmp_path / "b.xml"
    assert main(["mjcf", "--machine", "exact", "-o", str(base)]) == 0
    assert main(["mjcf", "--machine", "exact", "--design", "boom.L=0.32", "arm.Lc=0.7", "-o", str(moved)]) == 0
    a, b = mujoco.MjModel.from_xml_path(str(base)), mujoco.MjModel.from_xml_path(str(moved))
    assert np.max(np.abs(a.site_pos - b.site_pos)) > 1e-3
    data = mujoco.MjData(b)
    mujoco.mj_resetDataKeyframe(b, data, 0)
    mujoco.mj_forward(b, data)
    assert np.max(np.abs(data.efc_pos)) < 1e-12


@pytest.mark.parametrize(
    ("items", "words"),
    [
        (["boom.Q=1"], "boom.L, boom.Lc0"),
        (["boom.L"], "chain.var=value"),
        (["boom.L=abc"], "must be a number"),
        (["boom.L=5"], "[0.25, 0.34]"),
        (["boom.L=0.3", "boom.L=0.31"], "given twice"),
    ],
)
def test_machine_mjcf_refuses_a_bad_design_item_with_one_line(
    items: list[str], words: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A bad ``--design`` item exits 2 with one line and writes nothing."""
    out = tmp_path / "m.xml"
    assert main(["mjcf", "--machine", "exact", "--design", *items, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and words in err
    assert not out.exists()


def test_crane_mjcf_refuses_design_items_without_a_machine(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The crane path keeps ``--design`` for ``--from-result`` only."""
    assert main(["mjcf", "--design", "optimal", "-o", str(tmp_path / "c.xml")]) == 2
    assert "--from-result or --machine" in capsys.readouterr().err


def test_machine_mjcf_without_output_writes_machine_xml(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``mjcf --machine`` without ``-o`` writes machine.xml (not crane.xml); --crane beside it is refused."""
    monkeypatch.chdir(tmp_path)
    assert main(["mjcf", "--machine", "exact"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["machine.xml"]
    assert main(["mjcf", "--machine", "exact", "--crane", "xs031", "-o", "other.xml"]) == 2
    assert "--crane" in capsys.readouterr().err and not (tmp_path / "other.xml").exists()


def test_crane_naming_a_machine_file_is_an_alias_of_machine(tmp_path: Path) -> None:
    """``--crane exact`` or ``--crane <machine yaml>`` writes what ``--machine`` does; ``--crane xs031`` the crane."""
    from hiab_sim.resources import shipped_names

    machine_yaml = Path(str(shipped_names("machine")["exact"]))
    outputs = {}
    for name, argv in {
        "machine": ["--machine", "exact"],
        "crane name": ["--crane", "exact"],
        "crane file": ["--crane", str(machine_yaml)],
        "crane xs031": ["--crane", "xs031"],
    }.items():
        out = tmp_path / f"{name.replace(' ', '_')}.xml"
        assert main(["mjcf", *argv, "-o", str(out)]) == 0
        outputs[name] = out.read_text()
    assert outputs["crane name"] == outputs["machine"] == outputs["crane file"]
    assert outputs["crane xs031"] != outputs["machine"] and "telescope" in outputs["crane xs031"]


def test_crane_summary_of_a_machine_file_points_to_machine_show(capsys: pytest.CaptureFixture[str]) -> None:
    """``hiab-sim crane --crane exact``: one line naming ``machine show``, exit 2 (it summarises crane files)."""
    assert main(["crane", "--crane", "exact"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "hiab-sim machine show exact" in err

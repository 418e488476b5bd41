"""``hiab-sim render`` and ``hiab-sim mjcf --from-result`` on a machine file's result (the excavator)."""

from __future__ import annotations

import shutil
from pathlib import Path

import mujoco
import numpy as np
import pytest
from machine_result_helper import excavator_result

from hiab_sim.cli import main
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.mjcf_build import build_machine_model
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.model.mjcf import SOURCE_TO_WORLD


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return excavator_result(tmp_path_factory.mktemp("excavator"))


@pytest.mark.sim
def test_replayed_qpos_close_every_loop_and_put_the_tcp_where_the_kinematics_does(run_dir: Path) -> None:
    """Every frame's qpos holds the connect equalities and the TCP site sits on the forward kinematics' TCP."""
    from hiab_sim.render.machine_playback import load_machine_playback, machine_model_and_qpos

    data = load_machine_playback(run_dir)
    assert [m.name for m in data.designs] == ["initial", "optimal"]
    for motion in data.designs:
        machine = data.machine.with_design(motion.design)
        model, qpos = machine_model_and_qpos(machine, motion.position)
        state = mujoco.MjData(model)
        tcp = forward_kinematics(machine, motion.position).tcp_position @ SOURCE_TO_WORLD.T
        for k in range(0, len(qpos), 7):
            state.qpos[:] = qpos[k]
            mujoco.mj_forward(model, state)
            assert np.max(np.abs(state.efc_pos)) < 1e-12
            np.testing.assert_allclose(state.site("tcp").xpos, tcp[k], atol=1e-12)


@pytest.mark.sim
def test_render_frames_writes_pngs_of_both_designs(
    run_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``render RUN_DIR --frames DIR --count 2`` writes two PNGs; the initial and optimal designs differ on them."""
    import mediapy

    status = main(["render", str(run_dir), "--frames", str(tmp_path), "--count", "2", "--size", "320x240"])
    assert status == 0
    assert capsys.readouterr().out.strip() == f"wrote 2 frames to {tmp_path}"
    images = [mediapy.read_image(tmp_path / f"frame_{i:03d}.png") for i in range(2)]
    assert all(image.shape == (240, 320, 3) for image in images)
    assert np.mean(np.abs(images[0].astype(float) - images[1].astype(float))) > 0.5  # the machine moved


@pytest.mark.sim
def test_render_still_side_by_side(run_dir: Path, tmp_path: Path) -> None:
    """A still of the side-by-side layout: the two viewports show different designs (the halves differ)."""
    import mediapy

    out = tmp_path / "still.png"
    assert main(["render", str(run_dir), "--still", str(out), "--layout", "side-by-side", "--size", "320x180"]) == 0
    image = mediapy.read_image(out).astype(float)
    left, right = image[:, :160], image[:, 160:]
    assert np.mean(np.abs(left - right)) > 0.5


@pytest.mark.sim
@pytest.mark.parametrize("at", ["999", "-1", "nan"])
def test_a_still_outside_the_motion_is_refused(
    at: str, run_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--at outside the motion's time: one line naming --at and the span, exit 2, no file (it was clamped)."""
    out = tmp_path / "still.png"
    assert main(["render", str(run_dir), "--still", str(out), "--at", at, "--size", "160x120"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--at" in err and "must lie in [0," in err
    assert not out.exists()


@pytest.mark.sim
def test_render_refuses_simulate_on_a_machine_result(
    run_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Only the kinematic playback exists for a machine file's result: one line, exit 2, no file."""
    out = tmp_path / "v.mp4"
    assert main(["render", str(run_dir), "--mode", "simulate", "-o", str(out)]) == 2
    assert "kinematic only" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs Debian ffmpeg (scripts/setup.sh installs it)")
def test_render_result_plays_a_machine_result_as_optimize_does(run_dir: Path, tmp_path: Path) -> None:
    """``render_result``, the call ``optimize`` makes after a run, takes a machine file's result: one frame a tick.

    It read every result as a crane file's and failed on the machine designs' form, so ``optimize``
    of a machine study without ``--no-video`` exited 2 after writing its result.
    """
    import mediapy

    from hiab_sim.render import render_result
    from hiab_sim.render.machine_playback import load_machine_playback
    from hiab_sim.render.playback import frame_times

    output = render_result(run_dir, tmp_path / "clip.mp4", fps=4.0, size=(160, 120))
    assert output == tmp_path / "clip.mp4"
    assert len(mediapy.read_video(output)) == len(frame_times(load_machine_playback(run_dir).time, 4.0))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.mp4"]
    with pytest.raises(InvalidInputError, match="kinematic only"):
        render_result(run_dir, tmp_path / "sim.mp4", mode="simulate")
    assert not (tmp_path / "sim.mp4").exists()


@pytest.mark.sim
@pytest.mark.parametrize("design", ["initial", "optimal"])
def test_mjcf_from_machine_result_is_that_design(run_dir: Path, design: str, tmp_path: Path) -> None:
    """``mjcf --from-result RUN --design D`` writes the design the result stores (pins where the builder puts them)."""
    from hiab_sim.results.read import read_result, result_machine

    out = tmp_path / "m.xml"
    assert main(["mjcf", "--from-result", str(run_dir), "--design", design, "-o", str(out)]) == 0
    result = read_result(run_dir)
    values = (result.optimal if design == "optimal" else result.initial).lengths.as_array()  # type: ignore[union-attr]
    expected = build_machine_model(result_machine(run_dir, result), values)
    written = mujoco.MjModel.from_xml_path(str(out))
    np.testing.assert_allclose(written.site_pos, expected.site_pos, atol=1e-15)
    np.testing.assert_allclose(written.body_pos, expected.body_pos, atol=1e-15)


@pytest.mark.sim
def test_a_result_design_past_its_bound_by_the_solvers_tolerance_renders_and_exports(
    run_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """IPOPT may end 1e-8 relative past a bound: the result's design still renders and exports; a user's does not.

    The shipped digging study's optimum has boom.Lc 7.5e-9 m under its 0.47 m bound; ``optimize``
    then failed in its video. Designs read from a result are the solver's (its bounds, its tolerance);
    a design typed on the command line is checked against the file's bounds.
    """
    import json
    import shutil as files

    from hiab_sim.machine.loader import load_machine

    folder = tmp_path / "past_bound"
    files.copytree(run_dir, folder)
    document = json.loads((folder / "result.json").read_text(encoding="utf-8"))
    variable = load_machine("exact").decision_variables[2]
    past = variable.low - 5e-9 * max(1.0, abs(variable.low))
    document["optimal"]["lengths"]["values"][2] = past
    (folder / "result.json").write_text(json.dumps(document), encoding="utf-8")
    assert main(["mjcf", "--from-result", str(folder), "-o", str(tmp_path / "m.xml")]) == 0
    assert main(["render", str(folder), "--still", str(tmp_path / "s.png"), "--size", "160x120"]) == 0
    capsys.readouterr()
    typed = ["mjcf", "--machine", "exact", "--design", f"{variable.key}={past!r}", "-o", str(tmp_path / "u.xml")]
    assert main(typed) == 2
    assert variable.key in capsys.readouterr().err
    assert not (tmp_path / "u.xml").exists()


@pytest.mark.sim
def test_render_frames_of_a_crane_result(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--frames`` also serves a crane file's result: N PNGs, the first and last frames differ."""
    import mediapy
    from test_render import write_result

    from hiab_sim.crane.loader import load_crane

    folder = write_result(tmp_path / "result", load_crane("xs031"), samples=21)
    frames = tmp_path / "frames"
    frames.mkdir()
    assert main(["render", str(folder), "--frames", str(frames), "--count", "3", "--size", "320x240"]) == 0
    assert capsys.readouterr().out.strip() == f"wrote 3 frames to {frames}"
    first, last = (mediapy.read_image(frames / f"frame_{i:03d}.png").astype(float) for i in (0, 2))
    assert np.mean(np.abs(first - last)) > 0.5


@pytest.mark.sim
def test_render_frames_needs_an_existing_folder(
    run_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A missing ``--frames`` folder is one line, exit 2."""
    assert main(["render", str(run_dir), "--frames", str(tmp_path / "nowhere")]) == 2
    assert "--frames" in capsys.readouterr().err

"""Off-screen playback rendering: frames, camera, video files and one-line errors.

Renders through the OpenGL backend that hiab_sim selects (OSMesa on CI, MUJOCO_GL=osmesa) from a
fabricated result folder that follows the ``hiab-sim optimize`` contract: a smooth joint
trajectory inside the working ranges and two feasible link-length sets.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from playback_result_helper import write_playback_result

from hiab_sim import _gl
from hiab_sim.cli import main
from hiab_sim.crane.description import Crane
from hiab_sim.errors import InvalidInputError
from hiab_sim.model.mjcf import source_to_world
from hiab_sim.render import backend as render_backend
from hiab_sim.render import (
    fit_camera,
    frame_times,
    load_playback,
    playback_renderer,
    render_result,
    render_still,
)
from hiab_sim.render.frames import PlaybackRenderer

DURATION = 1.0  # [s] of the fabricated study
FPS = 12.0
SIZE = (320, 240)
FRAMES = int(DURATION * FPS) + 1


def write_result(folder: Path, crane: Crane, samples: int = 201) -> Path:
    """A result folder as ``hiab-sim optimize`` writes it."""
    return write_playback_result(folder, crane, DURATION, samples, "test")


@pytest.fixture(scope="module")
def result_dir(tmp_path_factory: pytest.TempPathFactory, crane: Crane) -> Path:
    return write_result(tmp_path_factory.mktemp("render") / "result", crane)


@pytest.fixture(scope="module")
def frames(result_dir: Path) -> np.ndarray:
    with playback_renderer(load_playback(result_dir), fps=FPS, size=SIZE) as renderer:
        return np.stack([renderer.frame(i) for i in range(len(renderer))])


def _saturated(image: np.ndarray) -> np.ndarray:
    """Mask of strongly coloured pixels: the tinted crane (floor, backdrop and sky are grey)."""
    rgb = image.astype(int)
    return (rgb.max(axis=-1) - rgb.min(axis=-1)) > 60


@pytest.mark.sim
def test_clip_has_one_frame_per_tick_at_the_video_size(frames: np.ndarray) -> None:
    """A 1 s study at 12 fps gives 13 RGB frames of 320x240 (real-time playback)."""
    assert frames.shape == (FRAMES, SIZE[1], SIZE[0], 3)
    assert frames.dtype == np.uint8
    assert len(frame_times(np.array([0.0, DURATION]), FPS)) == FRAMES


@pytest.mark.sim
def test_frames_show_both_cranes(frames: np.ndarray) -> None:
    """Every frame is lit (not black); each half holds crane pixels, the right half's tinted green (optimal)."""
    half = SIZE[0] // 2
    for image in frames:
        assert image.mean() > 60
        body = image[30:]  # below the captions
        assert _saturated(body[:, :half]).sum() > 300  # initial design, blue
        assert _saturated(body[:, half:]).sum() > 300  # optimal design, bluish green
        left, right = body[:, :half][_saturated(body[:, :half])], body[:, half:][_saturated(body[:, half:])]
        green_over_blue = [(int(p[:, 1].sum()) - int(p[:, 2].sum())) / len(p) for p in (left, right)]
        assert green_over_blue[1] - green_over_blue[0] > 20  # the right crane is the green one


@pytest.mark.sim
def test_consecutive_frames_differ_where_the_crane_moves(frames: np.ndarray) -> None:
    """The crane moves all along the trajectory, so every frame changes many pixels."""
    changed = np.any(frames[1:] != frames[:-1], axis=-1).sum(axis=(1, 2))
    assert np.all(changed > 200), changed


@pytest.mark.sim
def test_trail_follows_the_reference_in_mujoco_world(result_dir: Path) -> None:
    """The model's TCP site over the kinematic playback lies on the reference mapped (x, y, z) -> (x, -z, y)."""
    data = load_playback(result_dir)
    with playback_renderer(data, fps=FPS, size=SIZE) as renderer:
        at = frame_times(data.time, FPS)
        reference = np.stack([np.interp(at, data.time, c) for c in source_to_world(data.reference_tcp).T], axis=1)
        for design in renderer.designs:
            assert np.max(np.abs(design.tcp - reference)) < 2e-3


@pytest.mark.sim
def test_simulated_playback_tracks_the_plan(result_dir: Path) -> None:
    """Forward simulation under the inverse-dynamics forces keeps the TCP within 5 mm of the plan."""
    data = load_playback(result_dir)
    with playback_renderer(data, fps=FPS, size=SIZE, mode="simulate") as renderer:
        kinematic = playback_renderer(data, fps=FPS, size=SIZE)
        with kinematic:
            for simulated, planned in zip(renderer.designs, kinematic.designs, strict=True):
                assert np.max(np.linalg.norm(simulated.tcp - planned.tcp, axis=1)) < 5e-3


@pytest.mark.sim
def test_overlay_draws_both_designs_in_one_view(result_dir: Path) -> None:
    """Overlaid, one full-width view holds the opaque optimal crane and the ghost of the initial one."""
    with playback_renderer(load_playback(result_dir), fps=FPS, size=SIZE, layout="overlay") as renderer:
        assert [d.name for d in renderer.designs] == ["optimal", "initial"]
        image = renderer.frame(0)
    assert image.shape == (SIZE[1], SIZE[0], 3)
    assert _saturated(image[30:]).sum() > 600


@pytest.mark.sim
def test_stacked_layout_puts_one_design_above_the_other(result_dir: Path) -> None:
    """Stacked, the frame keeps its size and each half (top: initial, bottom: optimal) holds crane pixels."""
    with playback_renderer(load_playback(result_dir), fps=FPS, size=SIZE, layout="stacked") as renderer:
        image = renderer.frame(0)
    assert image.shape == (SIZE[1], SIZE[0], 3)
    half = SIZE[1] // 2
    for panel in (image[:half], image[half:]):
        assert _saturated(panel[25:]).sum() > 200


def _project(camera: object, point: np.ndarray, size: tuple[int, int], fovy: float) -> tuple[float, float]:
    """Pixel (column, row) of a world point through a free camera: an independent pinhole model."""
    from hiab_sim.render.camera import camera_axes

    forward, right, up = camera_axes(float(camera.azimuth), float(camera.elevation))  # type: ignore[attr-defined]
    eye = np.asarray(camera.lookat) - forward * float(camera.distance)  # type: ignore[attr-defined]
    v = point - eye
    tan_y = np.tan(np.radians(fovy) / 2.0)
    width, height = size
    x, y, z = v @ right / (v @ forward), v @ up / (v @ forward), 1.0
    return width / 2 * (1 + x / (tan_y * width / height) / z), height / 2 * (1 - y / tan_y / z)


def _luminance(rgb: np.ndarray) -> np.ndarray:
    """Relative luminance (sRGB, WCAG) of pixels (..., 3) uint8."""
    c = rgb.astype(float) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return linear @ np.array([0.2126, 0.7152, 0.0722])


@pytest.mark.sim
def test_dressed_frame_spans_the_machine_and_its_captions_read(result_dir: Path) -> None:
    """A 640x480 overlay frame shows the whole machine and readable captions.

    The design-coloured pixels reach from the column to the tool point as an independent pinhole
    model projects them, and the caption text has a contrast ratio above 4.5 (WCAG AA) on its box.
    """
    size = (640, 480)
    data = load_playback(result_dir)
    with playback_renderer(data, fps=FPS, size=size, layout="overlay") as renderer:
        index = len(renderer) // 2
        image = renderer.frame(index)
        optimal = renderer.designs[0]
        fovy = float(optimal.model.vis.global_.fovy)
        tool = _project(renderer.camera, optimal.tcp[index], size, fovy)
        column = _project(renderer.camera, np.zeros(3), size, fovy)
        caption_rows = renderer._captions[0].shape[0] + 8
    machine = _saturated(image)
    machine[:caption_rows] = False  # the captions are coloured too
    rows, cols = np.nonzero(machine)
    assert cols.max() - cols.min() > 0.4 * size[0] and rows.max() - rows.min() > 0.3 * size[1]
    margin = 30  # px: box sections and the tool block reach past the points projected
    assert cols.min() - margin <= min(tool[0], column[0]) and max(tool[0], column[0]) <= cols.max() + margin
    assert rows.min() - margin <= min(tool[1], column[1]) and max(tool[1], column[1]) <= rows.max() + margin
    assert 0 <= tool[0] < size[0] and 0 <= tool[1] < size[1] and 0 <= column[0] < size[0]
    band = image[4:caption_rows, : size[0] // 2]
    lum = _luminance(band)
    text, box = np.percentile(lum, 2), np.percentile(lum, 90)
    assert (box + 0.05) / (text + 0.05) > 4.5


def test_energy_notes_integrate_the_power_in_time() -> None:
    """Constant 1 kW for 2 s, no battery figure: the notes read 0, 1 and 2 kJ of 2 kJ at 0, 1 and 2 s."""
    from hiab_sim.render.video import energy_notes

    time = np.linspace(0.0, 2.0, 9)
    notes = energy_notes(time, np.array([0.0, 1.0, 2.0]), np.full(9, 1000.0))
    assert [n.split("net electrical energy")[1].split()[0] for n in notes] == ["0.000", "1.000", "2.000"]
    assert all(n.endswith("of 2.000 kJ (no battery figure)") for n in notes)
    assert energy_notes(time, np.array([0.5]), None)[0].startswith("t =  0.50 s")


def test_caption_bitmap_is_transparent_around_the_glyphs() -> None:
    """A caption stamps only its glyphs: most of its bitmap is transparent, so it hides nothing behind it."""
    from hiab_sim.render.labels import caption_bitmap

    bitmap = caption_bitmap("t = 3.00 s   E = 2.722 of 4.107 kJ", (0.0, 0.0, 1.0), 14)
    assert bitmap[..., 3].min() == 0.0 and bitmap[..., 3].mean() < 0.5


def test_fitted_camera_sees_every_point() -> None:
    """Every point projects inside the viewport and the extreme ones nearly touch its border."""
    rng = np.random.default_rng(1)
    points = rng.uniform([-1.0, -0.3, 0.0], [3.0, 0.3, 2.0], size=(200, 3))
    aspect, fovy = 4 / 3, 45.0
    camera = fit_camera(points, aspect, fovy, margin=1.0)
    az, el = np.radians(camera.azimuth), np.radians(camera.elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    eye = np.asarray(camera.lookat) - camera.distance * forward
    v = points - eye
    depth = v @ forward
    x = (v @ right) / (depth * np.tan(np.radians(fovy) / 2) * aspect)
    y = (v @ up) / (depth * np.tan(np.radians(fovy) / 2))
    assert np.all(depth > 0)
    assert np.max(np.maximum(np.abs(x), np.abs(y))) == pytest.approx(1.0, abs=1e-6)


def _count_frames(path: Path) -> int:
    if shutil.which("ffprobe"):
        out = subprocess.run(
            ["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
             "stream=nb_read_frames,width,height", "-of", "csv=p=0", str(path)],
            check=True, capture_output=True, text=True,
        ).stdout  # fmt: skip
        width, height, count = (int(v) for v in out.strip().split(","))
        assert (width, height) == SIZE
        return count
    import mediapy

    return len(mediapy.read_video(path))


@pytest.mark.e2e
@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs Debian ffmpeg (scripts/setup.sh installs it)")
def test_mp4_holds_every_frame_and_no_temporary_file(result_dir: Path, tmp_path: Path) -> None:
    """render_result writes an H.264 mp4 with one frame per tick and leaves nothing else behind."""
    output = render_result(result_dir, tmp_path / "clip.mp4", fps=FPS, size=SIZE)
    assert output == tmp_path / "clip.mp4"
    assert _count_frames(output) == FRAMES
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.mp4"]


@pytest.mark.sim
def test_still_frame_is_a_png_of_the_requested_size(result_dir: Path, tmp_path: Path) -> None:
    """--still writes one PNG frame."""
    import mediapy

    path = render_still(result_dir, tmp_path / "still.png", at_time=0.5, size=SIZE)
    assert mediapy.read_image(path).shape == (SIZE[1], SIZE[0], 3)
    with pytest.raises(InvalidInputError, match="--at"):  # outside the motion: refused, not clamped
        render_still(result_dir, tmp_path / "late.png", at_time=1e3, size=SIZE)
    assert not (tmp_path / "late.png").exists()


@pytest.mark.sim
def test_failed_render_leaves_no_video(result_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An error while frames are written removes the partial file: the output never exists half-written."""

    def broken(self: PlaybackRenderer, index: int) -> np.ndarray:
        if index == 3:
            raise RuntimeError("boom")
        return np.zeros((SIZE[1], SIZE[0], 3), dtype=np.uint8)

    monkeypatch.setattr(PlaybackRenderer, "frame", broken)
    with pytest.raises(RuntimeError, match="boom"):
        render_result(result_dir, tmp_path / "clip.mp4", fps=FPS, size=SIZE)
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------------------------------------
# Bad input: one line on stderr, exit status 2, no traceback, no file
# ---------------------------------------------------------------------------------------------


def _cli_error(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    assert main(["render", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


def test_missing_result_folder_is_one_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A folder that does not exist is named, with how to make one."""
    err = _cli_error(capsys, [str(tmp_path / "nope")])
    assert "does not exist" in err and "hiab-sim optimize" in err


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda f: (f / "result.json").write_text("{not json"), "not valid JSON"),
        (lambda f: (f / "trajectory.npz").write_bytes(b"garbage"), "not a valid .npz"),
        (lambda f: (f / "trajectory.npz").unlink(), "has no trajectory.npz"),
        (lambda f: (f / "result.json").write_text('{"crane": "xs031", "initial": {}}'), "initial.lengths"),
    ],
)
def test_corrupt_result_folder_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, crane: Crane, damage: object, message: str
) -> None:
    """A corrupt result.json or trajectory.npz is named on one line."""
    folder = write_result(tmp_path / "result", crane, samples=11)
    damage(folder)  # type: ignore[operator]
    assert message in _cli_error(capsys, [str(folder), "-o", str(tmp_path / "v.mp4")])
    assert not (tmp_path / "v.mp4").exists()


def test_unwritable_output_is_one_line(capsys: pytest.CaptureFixture[str], result_dir: Path, tmp_path: Path) -> None:
    """An output folder that does not exist, a folder as output, or a wrong suffix is refused up front."""
    assert "does not exist" in _cli_error(capsys, [str(result_dir), "-o", str(tmp_path / "no" / "v.mp4")])
    (tmp_path / "d.mp4").mkdir()
    assert "is a folder" in _cli_error(capsys, [str(result_dir), "-o", str(tmp_path / "d.mp4")])
    assert ".mp4 or .gif" in _cli_error(capsys, [str(result_dir), "-o", str(tmp_path / "v.avi")])


def test_missing_osmesa_is_one_line(
    capsys: pytest.CaptureFixture[str], result_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """MUJOCO_GL=osmesa without libOSMesa says to apt-get install libosmesa6."""
    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    monkeypatch.setattr(_gl.ctypes.util, "find_library", lambda name: None)
    err = _cli_error(capsys, [str(result_dir), "-o", str(tmp_path / "v.mp4")])
    assert "apt-get install libosmesa6" in err
    assert list(tmp_path.iterdir()) == []


def test_missing_ffmpeg_is_one_line(
    capsys: pytest.CaptureFixture[str], result_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without Debian ffmpeg or imageio-ffmpeg the error says how to install either."""
    monkeypatch.setattr(render_backend.shutil, "which", lambda name: None)
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)
    err = _cli_error(capsys, [str(result_dir), "-o", str(tmp_path / "v.mp4")])
    assert "apt-get install ffmpeg" in err and "pip install imageio-ffmpeg" in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.e2e
def test_cli_prints_nothing_at_exit(result_dir: Path, tmp_path: Path) -> None:
    """The GL contexts are freed before exit: the process's stderr stays empty (CI: MUJOCO_GL=osmesa)."""
    output = tmp_path / "still.png"
    done = subprocess.run(
        [sys.executable, "-m", "hiab_sim", "render", str(result_dir), "--still", str(output), "--size", "160x120"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert done.stdout.strip() == f"wrote still frame: {output}"

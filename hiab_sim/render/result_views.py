"""A result folder's playback video and still frame, a crane file's or a machine file's.

``render_result`` and ``render_still`` read which the folder holds
(:func:`~hiab_sim.render.machine_playback.is_machine_result`) and draw it: a crane file's result by
:mod:`hiab_sim.render.video` (a still at the frame of its 30 fps kinematic playback nearest the time
asked for), a machine file's by :mod:`hiab_sim.render.machine_video` (kinematic only; a still at that
time itself).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from hiab_sim.errors import InvalidInputError
from hiab_sim.render.backend import check_gl_backend
from hiab_sim.render.frames import Layout
from hiab_sim.render.machine_playback import is_machine_result
from hiab_sim.render.playback import Mode
from hiab_sim.render.video import DEFAULT_LAYOUT, crane_still, crane_video


def render_result(
    result_dir: str | Path,
    output: str | Path | None = None,
    fps: float = 30.0,
    size: tuple[int, int] = (640, 480),
    mode: Mode = "kinematic",
    layout: Layout = DEFAULT_LAYOUT,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Render the playback video (.mp4 or .gif) of a result folder; return its path.

    Args:
        result_dir: folder written by ``hiab-sim optimize`` (``result.json``, ``trajectory.npz``).
        output: video path (default ``result_dir/playback.mp4``); written atomically.
        fps: frames per second; the video plays in real time.
        size: (width, height) [px], both even for H.264.
        mode: ``"kinematic"`` (planned states) or ``"simulate"`` (forward simulation under the
            inverse-dynamics forces; a crane file's result only).
        layout: ``"stacked"``, ``"side-by-side"`` or ``"overlay"``.
        progress: called with (frames done, frames in all) after each frame.

    Raises:
        HiabSimError: bad result folder or output path, no OpenGL backend, no ffmpeg; ``mode``
            ``"simulate"`` for a machine file's result.

    """
    check_gl_backend()
    if is_machine_result(result_dir):
        if mode != "kinematic":
            raise InvalidInputError("--mode", mode, "a machine file's result plays back kinematic only")
        from hiab_sim.render.machine_video import render_machine_result

        return render_machine_result(result_dir, output, fps, size, layout, progress)
    return crane_video(result_dir, output, fps, size, mode, layout, progress)


def render_still(
    result_dir: str | Path,
    output: str | Path,
    at_time: float | None = None,
    size: tuple[int, int] = (640, 480),
    layout: Layout = DEFAULT_LAYOUT,
) -> Path:
    """Render one frame (.png) of the kinematic playback at ``at_time`` [s] (default: the end)."""
    check_gl_backend()
    if is_machine_result(result_dir):
        from hiab_sim.render.machine_video import machine_still

        return machine_still(result_dir, output, at_time, size, layout)
    return crane_still(result_dir, output, at_time, size, layout)

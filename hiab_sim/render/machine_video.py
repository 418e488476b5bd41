"""Videos, stills and quick frame sets of a machine file's result (see :mod:`hiab_sim.render.machine_playback`).

The layout and overlay are the crane's (:mod:`hiab_sim.render.video`): overlay (the optimal design
opaque, the initial one as a ghost), side by side or stacked; each design's caption, its battery
energy per cycle (or, without a battery figure, the drives' cumulative net energy), the reference
path and each design's TCP trail. Each design is dressed from the machine description
(:func:`~hiab_sim.render.dress_machine.machine_file_dress`: box-section links, barrels and rods,
pins, the tool, base and ground) with the task's payload drawn while held; the chain pivots that
the decision variables move are marked in each design's colour (:func:`~hiab_sim.render.dress_machine.moved_pivots`).
Only the kinematic playback exists for a machine file's result.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from hiab_sim.errors import InvalidInputError
from hiab_sim.render.backend import (
    check_gl_backend,
    check_output_path,
    ffmpeg_path,
    still_time,
    write_image,
    write_video,
)
from hiab_sim.render.decor import design_rgba
from hiab_sim.render.dress_machine import machine_file_dress, moved_pivots
from hiab_sim.render.frames import LAYOUTS, Design, Layout, PlaybackRenderer
from hiab_sim.render.machine_playback import (
    MachinePlayback,
    load_machine_playback,
    machine_model_and_qpos,
    machine_reference,
)
from hiab_sim.render.playback import frame_times, resample
from hiab_sim.render.video import DEFAULT_LAYOUT, VIDEO_NAME, design_texts, held_payload


def machine_renderer(
    data: MachinePlayback,
    fps: float = 30.0,
    size: tuple[int, int] = (640, 480),
    layout: Layout = DEFAULT_LAYOUT,
    at: np.ndarray | None = None,
) -> PlaybackRenderer:
    """A :class:`PlaybackRenderer` of both designs at ``fps`` (or at the instants ``at`` [s])."""
    if layout not in LAYOUTS:
        raise InvalidInputError("layout", layout, f"must be one of {', '.join(LAYOUTS)}")
    at = frame_times(data.time, fps) if at is None else np.asarray(at, dtype=float)
    designs = []
    marks = moved_pivots(data.machine, [motion.design for motion in data.designs])
    payload = held_payload(data, at)
    for motion in data.designs:
        designed = data.machine.with_design(motion.design, check_bounds=False)  # a result's: the solver's bounds
        model, qpos = machine_model_and_qpos(designed, resample(data.time, motion.position, at))
        caption, notes = design_texts(motion.name, layout, data, at, motion.power)
        dress = machine_file_dress(model, designed, data.ground)
        designs.append(
            Design(
                motion.name, model, qpos, design_rgba(motion.name), caption, notes,
                dress=dress, marks=marks, payload=payload,
            )
        )  # fmt: skip
    if layout == "overlay":
        designs.reverse()  # the optimal design opaque, the initial one as a translucent ghost
    return PlaybackRenderer(designs, machine_reference(data), size, layout=layout)


def render_machine_result(
    result_dir: str | Path,
    output: str | Path | None = None,
    fps: float = 30.0,
    size: tuple[int, int] = (640, 480),
    layout: Layout = DEFAULT_LAYOUT,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Render the playback video (.mp4 or .gif, written atomically) of a machine file's result; return its path."""
    check_gl_backend()
    data = load_machine_playback(result_dir)
    output = Path(result_dir) / VIDEO_NAME if output is None else Path(output)
    check_output_path(output, (".mp4", ".gif"), "video")
    ffmpeg_path()
    with machine_renderer(data, fps, size, layout) as renderer:
        return write_video(renderer, output, size, fps, progress)


def render_machine_frames(
    result_dir: str | Path,
    folder: str | Path,
    count: int,
    size: tuple[int, int] = (640, 480),
    layout: Layout = DEFAULT_LAYOUT,
) -> list[Path]:
    """Write ``count`` frames evenly spaced over the motion, ends included, as ``frame_<i>.png`` in ``folder``."""
    check_gl_backend()
    if count < 1:
        raise InvalidInputError("--count", count, "must be >= 1")
    folder = Path(folder)
    if not folder.is_dir():
        raise InvalidInputError("--frames", str(folder), "must be an existing folder")
    data = load_machine_playback(result_dir)
    at = np.linspace(data.time[0], data.time[-1], count)
    with machine_renderer(data, size=size, layout=layout, at=at) as renderer:
        return [write_image(folder / f"frame_{i:03d}.png", renderer.frame(i)) for i in range(len(renderer))]


def machine_still(
    result_dir: str | Path, output: str | Path, at_time: float | None, size: tuple[int, int], layout: Layout
) -> Path:
    """One frame (.png) of a machine file's result at ``at_time`` [s] (None: the end).

    Reached through :func:`hiab_sim.render.result_views.render_still`, which checks the OpenGL backend first.
    """
    output = check_output_path(Path(output), (".png",), "image")
    data = load_machine_playback(result_dir)
    t = still_time(at_time, float(data.time[0]), float(data.time[-1]))
    with machine_renderer(data, size=size, layout=layout, at=np.array([t])) as renderer:
        return write_image(output, renderer.frame(0))

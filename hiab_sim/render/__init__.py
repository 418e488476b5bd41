"""Off-screen playback videos of optimisation results.

Importing this package checks the OpenGL backend first (see :mod:`hiab_sim.render.backend`),
so a broken set-up gives a one-line :class:`~hiab_sim.errors.BackendUnavailableError` instead of
a failure deep inside PyOpenGL.
"""

from hiab_sim.render.backend import import_mujoco

import_mujoco()

from hiab_sim.render.camera import fit_camera  # noqa: E402
from hiab_sim.render.frames import Design, PlaybackRenderer  # noqa: E402
from hiab_sim.render.playback import (  # noqa: E402
    PlaybackData,
    frame_times,
    load_playback,
    planned_qpos,
    resample,
    simulated_qpos,
)
from hiab_sim.render.result_views import render_result, render_still  # noqa: E402
from hiab_sim.render.video import VIDEO_NAME, playback_renderer  # noqa: E402

__all__ = [
    "VIDEO_NAME",
    "Design",
    "PlaybackData",
    "PlaybackRenderer",
    "fit_camera",
    "frame_times",
    "load_playback",
    "planned_qpos",
    "playback_renderer",
    "render_result",
    "render_still",
    "resample",
    "simulated_qpos",
]

"""Off-screen playback videos of optimisation results.

Importing this package checks the OpenGL backend first (see :mod:`hiab_sim.render.backend`),
so a broken set-up gives a one-line :class:`~hiab_sim.errors.BackendUnavailableError` instead of
a failure deep inside PyOpenGL.
"""

from hiab_sim.render.backend import import_mujoco

import_mujoco()

from hiab_sim.render.camera import fit_camera  # noqa: E402
from hiab_sim.render.playback import frame_times, load_playback  # noqa: E402
from hiab_sim.render.result_views import render_result, render_still  # noqa: E402
from hiab_sim.render.video import playback_renderer  # noqa: E402

#: What scripts use (the CLI's render and optimize, the tests, the render benchmark); the rest from its module.
__all__ = ["fit_camera", "frame_times", "load_playback", "playback_renderer", "render_result", "render_still"]

"""``render_still``: one frame (.png) of a result folder, a crane file's or a machine file's.

A crane file's result is drawn at the frame of its 30 fps kinematic playback nearest the time asked
for (:func:`hiab_sim.render.video.crane_still`); a machine file's at that time itself
(:func:`hiab_sim.render.machine_video.machine_still`).
"""

from __future__ import annotations

from pathlib import Path

from hiab_sim.render.backend import check_gl_backend
from hiab_sim.render.frames import Layout
from hiab_sim.render.video import DEFAULT_LAYOUT, crane_still


def render_still(
    result_dir: str | Path,
    output: str | Path,
    at_time: float | None = None,
    size: tuple[int, int] = (640, 480),
    layout: Layout = DEFAULT_LAYOUT,
) -> Path:
    """Render one frame (.png) of the kinematic playback at ``at_time`` [s] (default: the end)."""
    from hiab_sim.render.machine_playback import is_machine_result

    check_gl_backend()
    if is_machine_result(result_dir):
        from hiab_sim.render.machine_video import machine_still

        return machine_still(result_dir, output, at_time, size, layout)
    return crane_still(result_dir, output, at_time, size, layout)

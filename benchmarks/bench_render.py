"""Frames per second of off-screen playback rendering at 640x480, with and without shadows/reflections.

Renders a 4 s XS 031 playback (both designs) through the backend hiab_sim selects (OSMesa on a
CPU-only machine) in the default fast visuals, then with shadows and reflections on, and
reports frames per second for each layout, the ratio, and the real-time factor at 30 fps.
Run: ``.venv/bin/python benchmarks/bench_render.py [--frames N]``.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from hiab_sim.crane.loader import load_crane
from hiab_sim.render import load_playback, playback_renderer
from hiab_sim.render.frames import LAYOUTS, Layout

# The benchmark renders the render tests' fabricated result (tests/ is a folder of modules, not a package).
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from playback_result_helper import write_playback_result


def write_demo_result(folder: Path, duration: float = 4.0, samples: int = 401) -> Path:
    """A result folder: a joint-space loop around (0.6, -1.3, 0.4), two designs."""
    return write_playback_result(folder, load_crane("xs031"), duration, samples, "bench")


def frames_per_second(folder: Path, layout: Layout, shadows: bool, frames: int, repeats: int = 3) -> float:
    """Best of ``repeats`` passes over ``frames`` frames (the machine may be shared)."""
    data = load_playback(folder)
    with playback_renderer(data, 30.0, (640, 480), "kinematic", layout, shadows=shadows) as renderer:
        renderer.frame(0)  # warm-up: first-use allocations in the GL driver
        count = min(frames, len(renderer))
        best = np.inf
        for _ in range(repeats):
            start = time.perf_counter()
            for index in range(count):
                renderer.frame(index)
            best = min(best, time.perf_counter() - start)
        return count / best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--frames", type=int, default=90, help="frames timed per case (default: 90)")
    args = parser.parse_args()
    print(f"MUJOCO_GL={os.environ.get('MUJOCO_GL', '(unset)')}, 640x480, {args.frames} frames per case")
    with tempfile.TemporaryDirectory() as tmp:
        folder = write_demo_result(Path(tmp))
        for layout in LAYOUTS:
            fast = frames_per_second(folder, layout, shadows=False, frames=args.frames)  # type: ignore[arg-type]
            slow = frames_per_second(folder, layout, shadows=True, frames=args.frames)  # type: ignore[arg-type]
            print(
                f"{layout:12s}  fast visuals {fast:6.1f} fps ({1e3 / fast:5.1f} ms/frame, {fast / 30:4.1f}x real time"
                f" at 30 fps) | shadows+reflections {slow:6.1f} fps ({1e3 / slow:5.1f} ms/frame)"
                f" | ratio {fast / slow:4.1f}x"
            )


if __name__ == "__main__":
    main()

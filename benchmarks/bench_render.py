"""Frames per second of off-screen playback rendering at 640x480, with and without shadows/reflections.

Renders a 4 s XS 031 playback (both designs) through the backend hiab_sim selects (OSMesa on a
CPU-only machine) in the default fast visuals, then with shadows and reflections on, and
reports frames per second for each layout, the ratio, and the real-time factor at 30 fps.
Run: ``.venv/bin/python benchmarks/bench_render.py [--frames N]``.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from hiab_sim.crane.description import LinkLengths
from hiab_sim.crane.kinematics import tcp_position
from hiab_sim.crane.loader import load_crane
from hiab_sim.render import load_playback, playback_renderer
from hiab_sim.render.frames import LAYOUTS, Layout


def write_demo_result(folder: Path, duration: float = 4.0, samples: int = 401) -> Path:
    """A result folder: a joint-space loop around (0.6, -1.3, 0.4), two designs."""
    crane = load_crane("xs031")
    initial = crane.default_lengths
    optimal = LinkLengths.from_array(initial.as_array() * np.array([1.03, 1.2, 1.0, 1.0, 1.0, 1.0]))
    t = np.linspace(0.0, duration, samples)
    w = 2.0 * np.pi / duration
    amp, freq, phase = np.array([0.25, 0.3, 0.3]), np.array([1.0, 1.0, 2.0]), np.array([0.0, 1.0, 0.0])
    arg = w * freq * t[:, None] + phase
    p = np.array([0.6, -1.3, 0.4]) + amp * np.sin(arg)
    v = amp * w * freq * np.cos(arg)
    a = -amp * (w * freq) ** 2 * np.sin(arg)

    def lengths(xi: LinkLengths) -> dict[str, dict[str, float]]:
        return {n: {"L": c.L, "Lc0": c.Lc0, "Lc": c.Lc} for n, c in zip(("lift", "tilt"), xi, strict=True)}

    result = {"crane": "xs031", "study": "bench", "initial": {"lengths": lengths(initial)}}
    result["optimal"] = {"lengths": lengths(optimal)}
    (folder / "result.json").write_text(json.dumps(result))
    arrays = {"time": t, "reference_tcp": tcp_position(crane, p[:, 0], p[:, 1], p[:, 2])}
    for d in ("initial", "optimal"):
        arrays |= {f"{d}_position": p, f"{d}_velocity": v, f"{d}_acceleration": a}
    np.savez(folder / "trajectory.npz", **arrays)
    return folder


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

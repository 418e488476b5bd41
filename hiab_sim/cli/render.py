"""``hiab-sim render``: a playback video of an optimisation result, rendered off-screen.

Needs an OpenGL backend (OSMesa on CPU: ``apt-get install libosmesa6``) and an ffmpeg binary
(``apt-get install ffmpeg`` or ``pip install imageio-ffmpeg``); a missing one is reported on one
line with exit status 2, and no half-written file is left behind.

A machine file's result (``machine:`` in the study) plays back in the machine's own MJCF
(:mod:`hiab_sim.render.machine_video`): both designs' joint samples, every chain body set from the
loop closure, in the crane's layouts and captions; kinematic only. ``--frames DIR [--count N]``
writes N frames evenly spaced over the motion as PNGs instead of a video (a quick look; needs no ffmpeg).
"""

from __future__ import annotations

import argparse
import re
import time
from pathlib import Path

import numpy as np

from hiab_sim.errors import InvalidInputError


def _size(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not match:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels, e.g. 640x480, got {text!r}")
    return int(match.group(1)), int(match.group(2))


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "render",
        help="Render a playback video of an optimisation result off-screen (initial vs optimal design).",
        description=(
            "Render the machine (crane file or machine file) following the study's trajectory with the initial "
            "and the optimal design: the machine drawn from its description (box-section booms, the cylinders' "
            "bores and rods, pins; a crane's column, truck bed, end mass, hook, the payload while it is held; an "
            "excavator's bucket and soil), the reference path of the tool (grey), each design's tool trail, the "
            "time and each design's battery energy per cycle (at the shared DC bus, from result.json; a result "
            "without one shows the drives' cumulative net energy, named as such). By default the optimal design "
            "is drawn over a ghost of the initial one, the pivots the decision variables move marked (a machine "
            "file's result: kinematic playback only). Off-screen through OSMesa (MUJOCO_GL=osmesa, selected "
            "automatically; MUJOCO_GL=egl is "
            "honoured)."
        ),
    )
    parser.add_argument("result_dir", metavar="RESULT_DIR", help="folder written by 'hiab-sim optimize'")
    parser.add_argument(
        "-o", "--output", metavar="VIDEO", help="video path, .mp4 or .gif (default: RESULT_DIR/playback.mp4)"
    )
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second, real-time playback (default: 30)")
    parser.add_argument("--size", type=_size, default=(640, 480), metavar="WxH", help="frame size (default: 640x480)")
    parser.add_argument(
        "--mode",
        choices=("kinematic", "simulate"),
        default="kinematic",
        help="kinematic: the planned states; simulate: a forward simulation driven by the computed "
        "actuator forces (default: kinematic)",
    )
    parser.add_argument(
        "--layout",
        choices=("stacked", "side-by-side", "overlay"),
        default="overlay",
        help="overlay: the optimal design over a ghost of the initial one, moved pivots marked; stacked or "
        "side-by-side: one viewport per design (default: overlay)",
    )
    parser.add_argument(
        "--still",
        metavar="FILE.png",
        help="write only one frame (kinematic) as a PNG instead of a video (see --at)",
    )
    parser.add_argument(
        "--at",
        type=float,
        metavar="SECONDS",
        help="time of the --still frame [s], within the motion (default: the end)",
    )
    parser.add_argument(
        "--frames",
        metavar="DIR",
        help="write --count frames evenly spaced over the motion as DIR/frame_<i>.png (DIR an existing folder) "
        "instead of a video",
    )
    parser.add_argument("--count", type=int, default=4, metavar="N", help="frames of --frames (default: 4)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Render the video (or the still frame, or the frames) and print where it was written."""
    from hiab_sim.render import render_result, render_still  # checks the OpenGL backend on import

    if not args.fps > 0:
        raise InvalidInputError("--fps", args.fps, "must be > 0", "1/s")
    start = time.perf_counter()
    from hiab_sim.render.machine_playback import is_machine_result

    machine = is_machine_result(args.result_dir)
    if machine and args.mode != "kinematic":
        raise InvalidInputError("--mode", args.mode, "a machine file's result plays back kinematic only")
    if args.frames:
        return _machine_frames(args) if machine else _crane_frames(args)
    if args.still:
        path = render_still(args.result_dir, args.still, at_time=args.at, size=args.size, layout=args.layout)
        print(f"wrote still frame: {path}")
        return 0
    output = Path(args.output) if args.output else None
    path = render_result(args.result_dir, output, fps=args.fps, size=args.size, mode=args.mode, layout=args.layout)
    print(f"wrote {args.mode} playback: {path} ({time.perf_counter() - start:.1f} s)")
    return 0


def _frames_folder(args: argparse.Namespace) -> Path:
    folder = Path(args.frames)
    if args.count < 1:
        raise InvalidInputError("--count", args.count, "must be >= 1")
    if not folder.is_dir():
        raise InvalidInputError("--frames", str(folder), "must be an existing folder")
    return folder


def _crane_frames(args: argparse.Namespace) -> int:
    """A crane file's result: ``--count`` frames of the kinematic playback."""
    from hiab_sim.render import load_playback, playback_renderer
    from hiab_sim.render.backend import write_image

    folder = _frames_folder(args)
    data = load_playback(args.result_dir)
    with playback_renderer(data, 30.0, args.size, "kinematic", args.layout) as renderer:
        picks = np.unique(np.linspace(0, len(renderer) - 1, args.count).round().astype(int))
        paths = [write_image(folder / f"frame_{i:03d}.png", renderer.frame(int(k))) for i, k in enumerate(picks)]
    print(f"wrote {len(paths)} frames to {folder}")
    return 0


def _machine_frames(args: argparse.Namespace) -> int:
    """A machine file's result: ``--count`` frames evenly spaced over the motion."""
    from hiab_sim.render.machine_video import render_machine_frames

    paths = render_machine_frames(args.result_dir, _frames_folder(args), args.count, args.size, args.layout)
    print(f"wrote {len(paths)} frames to {args.frames}")
    return 0

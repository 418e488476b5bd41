"""System back ends of rendering: the off-screen OpenGL context and the ffmpeg video writer.

Everything that can be missing on a headless machine is checked here and reported as a
:class:`~hiab_sim.errors.BackendUnavailableError` whose one-line message says how to install it:

- OpenGL: MuJoCo picks its backend from ``MUJOCO_GL`` when ``mujoco`` is first imported;
  :mod:`hiab_sim._gl` selects ``osmesa`` (CPU, ``apt-get install libosmesa6``) when unset, and a
  user's ``MUJOCO_GL=egl`` (GPU) is honoured.
- ffmpeg: mediapy pipes raw frames into an ``ffmpeg`` binary: Debian's ``ffmpeg``, else the
  binary of the ``imageio-ffmpeg`` wheel (it writes videos; mediapy cannot read them back with it).

Videos and images are written to a temporary name in the target folder and moved into place with
:func:`os.replace`, so a failed render never leaves a half-written file behind.
"""

from __future__ import annotations

import contextlib
import math
import os
import shutil
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from hiab_sim._gl import INSTALL_OSMESA, check_gl_backend, select_gl_backend
from hiab_sim.atomic_io import atomic_path
from hiab_sim.errors import BackendUnavailableError, HiabSimError, InvalidInputError

if TYPE_CHECKING:
    import mujoco

INSTALL_FFMPEG = "apt-get install ffmpeg (or pip install imageio-ffmpeg)"

#: Video containers written by :func:`video_sink`: suffix -> mediapy codec.
VIDEO_CODECS = {".mp4": "h264", ".gif": "gif"}


def import_mujoco() -> Any:
    """Import ``mujoco`` for rendering, turning a broken OpenGL set-up into a one-line error.

    With ``MUJOCO_GL=osmesa`` but no libOSMesa, ``import mujoco`` itself fails deep inside
    PyOpenGL (``'NoneType' object has no attribute 'glGetError'``); it is checked first. Rendering
    is where the backend is chosen (:func:`~hiab_sim._gl.select_gl_backend`: OSMesa when unset and
    installed); it takes effect when this is the first import of ``mujoco`` in the process.
    """
    select_gl_backend()
    check_gl_backend()
    try:
        import mujoco
    except (AttributeError, ImportError, OSError, RuntimeError) as error:
        backend = os.environ.get("MUJOCO_GL", "default")
        raise BackendUnavailableError(
            f"cannot load MuJoCo's OpenGL backend MUJOCO_GL={backend} ({error}); "
            f"for CPU rendering: {INSTALL_OSMESA} and MUJOCO_GL=osmesa"
        ) from None
    return mujoco


def open_renderer(model: mujoco.MjModel, width: int, height: int, max_geom: int) -> mujoco.Renderer:
    """Create an off-screen :class:`mujoco.Renderer`; sets the model's framebuffer to the image size.

    Raises:
        BackendUnavailableError: no OpenGL context can be created (no OSMesa, no display).

    """
    mujoco = import_mujoco()
    # The off-screen framebuffer exactly the image size: OSMesa clears and reads all of it.
    model.vis.global_.offwidth = width
    model.vis.global_.offheight = height
    try:
        with warnings.catch_warnings():  # GLFW warns about a missing display before it fails
            warnings.simplefilter("ignore")
            return mujoco.Renderer(model, height=height, width=width, max_geom=max_geom)
    except (mujoco.FatalError, ImportError, RuntimeError, AttributeError) as error:
        backend = check_gl_backend()
        first_line = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise BackendUnavailableError(
            f"no off-screen OpenGL context (MUJOCO_GL={backend}: {first_line}); "
            f"install OSMesa with {INSTALL_OSMESA} and set MUJOCO_GL=osmesa, or use MUJOCO_GL=egl on a GPU"
        ) from None


def ffmpeg_path() -> str:
    """Path of the ffmpeg binary mediapy will use: Debian's ``ffmpeg``, else imageio-ffmpeg's.

    Raises:
        BackendUnavailableError: neither is installed.

    """
    import mediapy

    found = shutil.which("ffmpeg")
    if found:
        return found
    try:
        import imageio_ffmpeg

        found = str(imageio_ffmpeg.get_ffmpeg_exe())
    except (ImportError, RuntimeError):
        raise BackendUnavailableError(f"ffmpeg is not installed: {INSTALL_FFMPEG}") from None
    mediapy.set_ffmpeg(found)
    return found


def check_output_path(path: Path, suffixes: tuple[str, ...], what: str) -> Path:
    """Validate an output file path: known suffix, existing writable folder; return it resolved."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise InvalidInputError(f"{what} path", str(path), f"must end with {' or '.join(suffixes)}")
    folder = path.parent
    if not folder.is_dir():
        raise HiabSimError(f"cannot write the {what} {path}: folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise HiabSimError(f"cannot write the {what} {path}: folder {folder} is not writable")
    if path.is_dir():
        raise HiabSimError(f"cannot write the {what} {path}: it is a folder")
    return path


def still_time(at_time: float | None, start: float, end: float) -> float:
    """The time [s] of a still frame: ``at_time`` (``--at``) within the motion's [start, end], None the end."""
    if at_time is None:
        return end
    if not (math.isfinite(at_time) and start <= at_time <= end):
        raise InvalidInputError("--at", at_time, f"must lie in [{start:g}, {end:g}] (the motion's time)", "s")
    return float(at_time)


class VideoSink:
    """An open video file: :meth:`add` frames one by one; the file appears when the sink closes."""

    def __init__(self, writer: Any) -> None:
        self._writer = writer
        self.frames = 0

    def add(self, frame: NDArray[np.uint8]) -> None:
        """Append one RGB frame (H, W, 3) uint8."""
        self._writer.add_image(frame)
        self.frames += 1


@contextlib.contextmanager
def video_sink(path: Path, size: tuple[int, int], fps: float) -> Iterator[VideoSink]:
    """Open ``path`` (.mp4 H.264 or .gif) for frames of ``size`` = (width, height) at ``fps``.

    The video is encoded by ffmpeg while frames arrive; on any error nothing is left at ``path``.
    """
    import mediapy

    path = check_output_path(path, tuple(VIDEO_CODECS), "video")
    ffmpeg_path()
    width, height = size
    with atomic_path(path) as temporary:
        writer = mediapy.VideoWriter(temporary, (height, width), codec=VIDEO_CODECS[path.suffix.lower()], fps=fps)
        try:
            with writer:
                yield VideoSink(writer)
        except RuntimeError as error:
            if "Error writing" not in str(error):
                raise
            detail = str(error).strip().splitlines()[-1]
            raise BackendUnavailableError(f"ffmpeg could not write {path}: {detail}") from None


class FrameSource(Protocol):
    """Frames by index: a renderer of a playback."""

    def __len__(self) -> int:
        """Number of frames."""
        ...

    def frame(self, index: int) -> NDArray[np.uint8]:
        """Frame ``index`` as RGB (H, W, 3) uint8."""
        ...


def write_video(
    frames: FrameSource,
    path: Path,
    size: tuple[int, int],
    fps: float,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Encode every frame of ``frames`` into ``path`` (:func:`video_sink`), reporting ``progress(done, total)``."""
    with video_sink(path, size, fps) as sink:
        for index in range(len(frames)):
            sink.add(frames.frame(index))
            if progress is not None:
                progress(index + 1, len(frames))
    return path


def write_image(path: Path, image: NDArray[np.uint8]) -> Path:
    """Write an RGB image (PNG) atomically."""
    import mediapy

    path = check_output_path(path, (".png",), "image")
    with atomic_path(path) as temporary:
        mediapy.write_image(temporary, image)
    return path

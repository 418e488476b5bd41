"""Choose MuJoCo's OpenGL backend before ``mujoco`` is first imported.

MuJoCo reads ``MUJOCO_GL`` once, at import. hiab-sim renders off-screen, so when the user has
not chosen a backend and the OSMesa library is installed, it selects ``osmesa``; a user's own
choice (for example ``MUJOCO_GL=egl``) is always honoured. Without OSMesa nothing is set, so
the physics still imports; rendering then reports how to install it.
"""

from __future__ import annotations

import ctypes.util
import os


def select_gl_backend() -> str | None:
    """Set ``MUJOCO_GL=osmesa`` if unset and OSMesa is available; return the backend in force."""
    if "MUJOCO_GL" not in os.environ and ctypes.util.find_library("OSMesa"):
        os.environ["MUJOCO_GL"] = "osmesa"
    return os.environ.get("MUJOCO_GL")

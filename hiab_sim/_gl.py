"""Choose MuJoCo's OpenGL backend before ``mujoco`` is first imported.

MuJoCo reads ``MUJOCO_GL`` once, at import. hiab-sim renders off-screen, so when the user has
not chosen a backend and the OSMesa library is installed, it selects ``osmesa``; a user's own
choice (for example ``MUJOCO_GL=egl``) is always honoured. Without OSMesa nothing is set, so
the physics still imports; rendering then reports how to install it.
"""

from __future__ import annotations

import ctypes.util
import os

from hiab_sim.errors import BackendUnavailableError

INSTALL_OSMESA = "apt-get install libosmesa6"


def select_gl_backend() -> str | None:
    """Set ``MUJOCO_GL=osmesa`` if unset and OSMesa is available; return the backend in force."""
    if "MUJOCO_GL" not in os.environ and ctypes.util.find_library("OSMesa"):
        os.environ["MUJOCO_GL"] = "osmesa"
    return os.environ.get("MUJOCO_GL")


def check_gl_backend() -> str:
    """Return the OpenGL backend in force; raise if it is OSMesa and libOSMesa is missing.

    With ``MUJOCO_GL=osmesa`` but no libOSMesa, ``import mujoco`` itself fails deep inside
    PyOpenGL; every subcommand that imports MuJoCo checks this first and reports one line.
    """
    backend = os.environ.get("MUJOCO_GL", "").strip().lower()
    if backend == "osmesa" and not ctypes.util.find_library("OSMesa"):
        raise BackendUnavailableError(
            f"MUJOCO_GL=osmesa but libOSMesa is not installed: {INSTALL_OSMESA} (or unset MUJOCO_GL)"
        )
    return backend or "default"

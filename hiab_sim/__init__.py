"""hiab-sim: energy-optimal EMLA mounting for HIAB parallel-serial loader cranes."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from hiab_sim._gl import select_gl_backend

select_gl_backend()  # must run before anything imports mujoco

from hiab_sim.errors import ConfigError, HiabSimError, InvalidInputError, SolverError  # noqa: E402

try:
    __version__ = version("hiab-sim")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

__all__ = ["ConfigError", "HiabSimError", "InvalidInputError", "SolverError", "__version__"]

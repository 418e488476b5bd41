"""hiab-sim: where to mount the electromechanical linear actuators of a parallel-serial machine.

The Python API (:mod:`hiab_sim.api`)::

    import hiab_sim as hs

    study = hs.load_study("xs031_spiral")  # a shipped name or a path
    result = hs.optimize(study, out="runs/x")  # typed result, the files the CLI writes
    e = hs.evaluate(study, lengths, trajectory="fixed")  # or "reoptimize"
    r = hs.read_result("runs/x")

Importing the package changes nothing in the environment: the OpenGL backend of MuJoCo is chosen
when rendering starts (:mod:`hiab_sim._gl`). The first use of the study API loads threadpoolctl,
which sets ``KMP_DUPLICATE_LIB_OK=True`` where it is unset (its own workaround, kept: a process
with two OpenMP runtimes aborts without it); hiab-sim sets nothing else.
"""

from __future__ import annotations

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version
from typing import TYPE_CHECKING, Any

from hiab_sim.errors import (
    BackendUnavailableError,
    ConfigError,
    HiabSimError,
    InfeasibleStudyError,
    InvalidInputError,
    SolverError,
)

if TYPE_CHECKING:
    from hiab_sim.api import DesignEvaluation, TaskEvaluation, evaluate, load_study, optimize, read_result

#: Names of :mod:`hiab_sim.api`, imported when first used so that ``import hiab_sim`` (and the CLI's
#: ``--help``) stays light.
_API = ("DesignEvaluation", "TaskEvaluation", "evaluate", "load_study", "optimize", "read_result")


def __getattr__(name: str) -> Any:
    if name in _API:
        return getattr(import_module("hiab_sim.api"), name)
    raise AttributeError(f"module 'hiab_sim' has no attribute {name!r}")


try:
    __version__ = version("hiab-sim")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

__all__ = [
    "BackendUnavailableError",
    "ConfigError",
    "DesignEvaluation",
    "HiabSimError",
    "InfeasibleStudyError",
    "InvalidInputError",
    "SolverError",
    "TaskEvaluation",
    "__version__",
    "evaluate",
    "load_study",
    "optimize",
    "read_result",
]

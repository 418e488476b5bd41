"""Study YAML -> frozen dataclasses: crane, EMLAs, spline, grid, tasks (references, payloads), bounds, solver.

A study file names everything the optimiser of seed eqs. ``costf2`` / ``const_a``..``const_m``
needs; every unknown or missing key raises :class:`~hiab_sim.errors.ConfigError` and every
out-of-range value :class:`~hiab_sim.errors.InvalidInputError` naming the field. Values are read
by :mod:`hiab_sim.yaml_fields`; each dataclass checks its own ranges in ``__post_init__`` and
holds the only copy of its defaults (a key a file omits takes the dataclass default). The crane
and the EMLA set are a preset name or a path, resolved by :func:`hiab_sim.resources.locate`:
relative paths next to the study file (inside the installed package for a shipped study).

The study's work is a tuple of tasks (:mod:`hiab_sim.study.spec.tasks`): a ``tasks:`` list, or today's
single ``reference:`` (+ ``payload:``), which is one task named after the study with weight 1. In
that single-reference form a plain ``payload: <kg>`` keeps today's meaning, the payload's weight
only (``Payload(mass, inertia=False)``), so the results of existing study files do not change;
within ``tasks:`` a plain number is a constant mass with its inertia (see :mod:`.payload`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.crane.description import CHAIN_NAMES, ChainLengths, Crane, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.crane.mounting import MountingSpace
from hiab_sim.emla.config import load_emla_set
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import DEFAULT_STUDY, Source, locate
from hiab_sim.structure.pin_loads import pins
from hiab_sim.structure.settings import StructureSettings
from hiab_sim.study.machines.crane_model import CraneModel
from hiab_sim.study.spec.energy import ENERGY_KEYS
from hiab_sim.study.spec.machine_study import machine_study_from_dict
from hiab_sim.study.spec.settings import (
    ID_PATHS,
    Bounds,
    GridSettings,
    SolverSettings,
    SplineSettings,
    Tracking,
    bounds_from_mapping,
    shared_sections,
    work_sections,
)
from hiab_sim.study.spec.study import Study
from hiab_sim.study.spec.tasks import column_names
from hiab_sim.yaml_fields import mapping, positive, read_yaml

_TOP = {
    "name",
    "crane",
    "machine",
    "tracked",
    "emla",
    "initial_lengths",
    "spline",
    "grid",
    "reference",
    "tracking",
    "bounds",
    "solver",
    "payload",
    *ENERGY_KEYS,
    "tasks",
    "build",
    "mounting",
    "structure",
}
_REQUIRED_TOP = {"bounds"}


def load_study(path: str | Path | Source | None = None) -> Study:
    """Load and validate a study: a shipped name (``xs031_spiral``, the default) or a YAML path.

    Raises:
        ConfigError: Missing file, malformed YAML, unknown or missing keys, wrong types.
        InvalidInputError: A value out of range, named by its field; ``path`` neither a name nor a path.

    """
    if isinstance(path, Source):
        found = path
    elif path is not None and not isinstance(path, (str, Path)):
        raise InvalidInputError("study", path, "must be a shipped study name, a YAML path or a loaded Study")
    else:
        found = locate(DEFAULT_STUDY if path is None else path, "study")
    return study_from_dict(read_yaml(found), found)


def study_from_dict(data: Any, file: str | Path | Source = "<study>") -> Study:
    """Build a :class:`Study` from a parsed YAML mapping (relative paths resolve next to ``file``)."""
    if not isinstance(file, Source):
        file = Source(str(file), Path(file), shipped=False)
    top = mapping(data, "study", _TOP, _REQUIRED_TOP)
    if "machine" in top:
        return machine_study_from_dict(dict(top), file)
    if "crane" not in top:
        raise ConfigError("study: missing key 'crane' (a crane file) or 'machine' (a machine file)")
    if "tracked" in top:
        raise ConfigError("study: 'tracked' belongs to a machine file's study (machine:); a crane tracks x, y, xt2")
    crane_source = str(top["crane"])
    crane_file = locate(crane_source, "crane", relative_to=file)
    crane = load_crane(crane_file)
    emla_source = "default" if top.get("emla") is None else str(top["emla"])
    emlas = load_emla_set(locate(emla_source, "emla", relative_to=file)).renamed(CraneModel(crane).actuator_names)
    bounds = bounds_from_mapping(top["bounds"])
    work = work_sections(top, file, column_names(CraneModel(crane)))
    initial = _lengths(top.get("initial_lengths"), crane, bounds)
    moved = "initial_lengths" not in top and initial != crane.default_lengths
    return Study(
        **work,
        crane_source=crane_source,
        crane_description=crane,
        emla_source=emla_source,
        emlas=emlas,
        initial_lengths=initial,
        bounds=bounds,
        **shared_sections(top),
        mounting=None if top.get("mounting") is None else MountingSpace.from_mapping(top["mounting"]),
        crane_file=crane_file,
        start_moved_from=crane.default_lengths if moved else None,
        structure=StructureSettings.from_mapping(top.get("structure"), [pin.name for pin in pins(crane)]),
    )


def _lengths(data: Any, crane: Crane, bounds: Bounds) -> LinkLengths:
    if data is None:  # the crane's own lengths, clipped into the bounds (the feasibility phase moves on from there)
        return _clipped_lengths(crane, bounds)
    top = mapping(data, "initial_lengths", set(CHAIN_NAMES), set(CHAIN_NAMES))
    chains = []
    for name in CHAIN_NAMES:
        d = mapping(top[name], f"initial_lengths.{name}", {"L", "Lc0", "Lc"}, {"L", "Lc0", "Lc"})
        values = [positive(d[k], f"initial_lengths.{name}.{k}", "m") for k in ("L", "Lc0", "Lc")]
        chains.append(ChainLengths(*values))
    return LinkLengths(chains[0], chains[1])


def _clipped_lengths(crane: Crane, bounds: Bounds) -> LinkLengths:
    """The crane's lengths if inside the bounds; else L clipped and x0 = Lc0 + Lc centring the joint range's stroke.

    A clipped L moves the strokes at the ends of the joint range (eq. qus_a); x0 is chosen so the
    stroke used, s(theta_up) - s(theta_low), sits in the middle of [0, stroke], and Lc takes what
    Lc0 (clipped) leaves, within its bounds. The feasibility phase starts from this point.
    """
    xi = crane.default_lengths.as_array()
    low, up = np.asarray(bounds.xi_low), np.asarray(bounds.xi_up)
    if np.all((low <= xi) & (xi <= up)):
        return crane.default_lengths
    out = np.clip(xi, low, up)
    for j, chain in enumerate(crane.chains):
        if out[3 * j] == xi[3 * j]:
            continue
        q = chain.joint_offset - math.pi - np.asarray(chain.joint_range)  # hinge angle (eq. thetas)
        s = np.sqrt(out[3 * j] ** 2 + chain.L1**2 - 2.0 * out[3 * j] * chain.L1 * np.cos(q))
        x0 = 0.5 * (float(s.min() + s.max()) - chain.stroke)
        out[3 * j + 2] = float(np.clip(x0 - out[3 * j + 1], low[3 * j + 2], up[3 * j + 2]))
    return LinkLengths.from_array(out)


__all__ = [
    "DEFAULT_STUDY",
    "ID_PATHS",
    "Bounds",
    "GridSettings",
    "SolverSettings",
    "SplineSettings",
    "Study",
    "Tracking",
    "load_study",
    "study_from_dict",
]

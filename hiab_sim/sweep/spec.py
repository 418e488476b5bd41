"""Sweep file -> validated points: a base study and a grid or a Latin-hypercube sample over dotted paths.

A sweep file (YAML)::

    name: xs031_payload_gear          # optional (default: the file's stem)
    study: xs031_spiral               # a shipped study name, or a path relative to this file
    set: {solver.maxiter: 60}         # optional: the same value at every point
    grid:                             # full factorial over its axes, in file order ...
      payload: [0, 150, 300]          #   an axis over one path
      opening_percent:                #   a zipped axis: these paths move together;
        values: [0, 20, 40]           #   optional "values": the axis's own coordinate (a table column)
        bounds.lift.low[0]: [...]
        bounds.lift.up[0]: [...]
    sample:                           # ... or a Latin-hypercube sample (scipy.stats.qmc, seeded)
      points: 20
      seed: 1
      ranges: {payload: [0, 300], emla.lift.gear_ratio: [3, 8]}

Paths address the study's YAML mapping (``payload``, ``solver.maxiter``, a crane file's chain bounds
``bounds.lift.up[0]``; a machine file's study has none, its bounds are the machine file's, and a sweep
over ``machine`` with paths of copies of that file moves them; an item of a list the study leaves to
its default, such as a crane study's ``bounds.joint_velocity[0]`` without ``bounds.joint_velocity``,
is refused: the default is not filled in, give the list in the study or sweep it whole);
paths under ``emla.`` address the study's EMLA file (``emla.lift.gear_ratio`` is its
``actuators.lift.gear_ratio``, ``emla.pmsm.peak_torque`` its ``pmsm.peak_torque``; an actuator is
any name under the file's ``actuators``, e.g. ``emla.boom.gear_ratio`` of the eXact arm's). The base
study may be a crane file's (``crane:``) or a machine file's (``machine:``), of one task or a duty
mix: a point is a whole optimisation of that study. Every point's
study (and EMLA set) is built and validated here, before any work starts: an unknown path, an
empty grid or a value the study rejects raises :class:`~hiab_sim.errors.ConfigError` naming the path.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hiab_sim.emla.config import emla_set_from_mapping
from hiab_sim.errors import ConfigError, HiabSimError
from hiab_sim.resources import Source, locate
from hiab_sim.study.spec.study import Study
from hiab_sim.study.spec.study_file import study_from_dict
from hiab_sim.sweep.paths import parse_path, set_path
from hiab_sim.yaml_fields import mapping, read_yaml

_TOP = {"name", "study", "set", "grid", "sample"}


@dataclass(frozen=True)
class Point:
    """One point: its key (hash of its values), parameter values, and the documents of its study."""

    key: str
    values: dict[str, Any]  # path (or axis name) -> value, in column order
    study: dict[str, Any]  # study mapping; crane and EMLA paths absolute (EMLA "default" or a path)
    emla: dict[str, Any] | None  # the EMLA mapping when the sweep changes it, else None


@dataclass(frozen=True)
class Sweep:
    """A validated sweep: name, files, content digest and its points in table order."""

    name: str
    file: Path
    study_file: Path
    digest: str
    columns: tuple[str, ...]
    points: tuple[Point, ...]
    axes: tuple[str, ...]  # one column per independent axis (a zipped axis: its values or first path)
    design_names: tuple[str, ...]  # the base study's machine's decision variables, in the order of Xi


def resolve_study(name: str, sweep_file: Path) -> Path:
    """A shipped study name or a study path (next to the sweep file first), as a file path."""
    found = locate(name, "study", relative_to=_user_file(sweep_file))
    return Path(str(found.file))


def _user_file(path: Path) -> Source:
    return Source(str(path), path, shipped=False)


def _absolute(study: dict[str, Any], study_file: Path) -> dict[str, Any]:
    """The study mapping with its crane and EMLA paths made absolute (preset names kept)."""
    out = copy.deepcopy(study)
    for key in ("crane", "emla"):
        value = out.get(key)
        if value is None:
            continue
        found = locate(str(value), key, relative_to=_user_file(study_file))
        if not (found.shipped and found.label == str(value)):  # a file, not a preset name
            out[key] = str(found.file)
    return out


def _axes(grid: Any, where: str) -> list[tuple[str | None, dict[str, list[Any]]]]:
    """Grid axes: (axis name or None, {path: values}), each axis's lists of one length >= 1."""
    if not isinstance(grid, dict) or not grid:
        raise ConfigError(f"{where}: expected a non-empty mapping of paths to lists of values")
    axes: list[tuple[str | None, dict[str, list[Any]]]] = []
    for name, spec in grid.items():
        if isinstance(spec, list):
            if not spec:
                raise ConfigError(f"{where}.{name}: empty list of values")
            axes.append((None, {str(name): spec}))
            continue
        if not isinstance(spec, dict) or not spec:
            raise ConfigError(f"{where}.{name}: expected a list of values or a mapping of paths to lists")
        lengths = set()
        for path, values in spec.items():
            if not isinstance(values, list) or not values:
                raise ConfigError(f"{where}.{name}.{path}: expected a non-empty list of values")
            lengths.add(len(values))
        if len(lengths) != 1:
            raise ConfigError(f"{where}.{name}: the lists of a zipped axis must have one length, got {sorted(lengths)}")
        axes.append((str(name), {str(p): v for p, v in spec.items()}))
    return axes


def _grid_points(grid: Any) -> tuple[list[str], list[dict[str, Any]], list[str]]:
    axes = _axes(grid, "grid")
    main = [str(name) if name is not None and "values" in paths else next(iter(paths)) for name, paths in axes]
    columns: list[str] = []
    for name, paths in axes:
        columns += [name] if name is not None and "values" in paths else []
        columns += [p for p in paths if p != "values"]
    points = []
    for combo in itertools.product(*[range(len(next(iter(paths.values())))) for _, paths in axes]):
        values: dict[str, Any] = {}
        for (name, paths), k in zip(axes, combo, strict=True):
            for path, items in paths.items():
                values[str(name) if path == "values" else path] = items[k]
        points.append({c: values[c] for c in columns})
    return columns, points, main


def _sample_points(sample: Any) -> tuple[list[str], list[dict[str, Any]], list[str]]:
    from scipy.stats import qmc

    mapping(sample, "sample", {"points", "seed", "ranges"}, {"points", "ranges"})
    n, seed, ranges = sample.get("points"), sample.get("seed", 0), sample["ranges"]
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ConfigError(f"sample.points: expected an integer >= 1, got {n!r}")
    if not isinstance(ranges, dict) or not ranges:
        raise ConfigError("sample.ranges: expected a non-empty mapping of paths to [low, high]")
    low, high = [], []
    for path, pair in ranges.items():
        ok = isinstance(pair, list) and len(pair) == 2 and all(isinstance(v, int | float) for v in pair)
        if not ok or not pair[0] < pair[1]:
            raise ConfigError(f"sample.ranges.{path}: expected [low, high] numbers with low < high, got {pair!r}")
        low.append(float(pair[0]))
        high.append(float(pair[1]))
    unit = qmc.LatinHypercube(d=len(ranges), seed=int(seed)).random(n)
    scaled = qmc.scale(unit, low, high)
    columns = [str(p) for p in ranges]
    return columns, [{c: float(row[k]) for k, c in enumerate(columns)} for row in scaled], columns


def point_key(values: dict[str, Any]) -> str:
    """Identity of a point: SHA-256 (16 hex digits) of its parameter values."""
    return hashlib.sha256(json.dumps(values, sort_keys=True, default=str).encode()).hexdigest()[:16]


def load_sweep(path: str | Path) -> Sweep:
    """Load a sweep file and validate every point's study before any work starts.

    Raises:
        ConfigError: Malformed file, unknown path, empty grid, or a value the study (or the EMLA
            set) rejects; the message names the path and the value.

    """
    file = Path(str(locate(str(path), "study").file))
    data = read_yaml(_user_file(file))
    if not isinstance(data, dict):
        raise ConfigError(f"{file}: a sweep file is a mapping with study and grid or sample")
    unknown = set(data) - _TOP
    if unknown:
        raise ConfigError(f"{file}: unknown key(s) {', '.join(sorted(unknown))}; allowed: {', '.join(sorted(_TOP))}")
    if "study" not in data:
        raise ConfigError(f"{file}: missing key study (a shipped study name or a path relative to the sweep file)")
    if ("grid" in data) == ("sample" in data):
        raise ConfigError(f"{file}: give exactly one of grid (full factorial) or sample (Latin hypercube)")
    study_file = resolve_study(str(data["study"]), file)
    base = _absolute(read_yaml(_user_file(study_file)), study_file)
    fixed = data.get("set", {}) or {}
    if not isinstance(fixed, dict):
        raise ConfigError("set: expected a mapping of paths to values")
    base_study = _validate(base, None, study_file, [])
    design_names = tuple(base_study.model.design_names)
    columns, raw, axes = _grid_points(data["grid"]) if "grid" in data else _sample_points(data["sample"])
    paths = [c for c in columns if c not in _axis_names(data)]
    if base_study.machine is not None:
        for p in [*fixed, *paths]:
            _check_machine_bounds(str(p), base_study)
    emla_base = _emla_document(base) if any(p.startswith("emla.") for p in [*fixed, *paths]) else None
    points = []
    for values in raw:
        study, emla = copy.deepcopy(base), copy.deepcopy(emla_base)
        assignments = list(fixed.items()) + [(p, values[p]) for p in paths]
        for p, v in assignments:
            _assign(study, emla, p, copy.deepcopy(v))
        _validate(study, emla, study_file, assignments)
        points.append(Point(point_key(values), values, study, emla))
    content = json.dumps({"sweep": data, "study": base, "emla": emla_base}, sort_keys=True, default=str)
    return Sweep(
        name=str(data.get("name", file.stem)),
        file=file,
        study_file=study_file,
        digest=hashlib.sha256(content.encode()).hexdigest(),
        columns=tuple(columns),
        points=tuple(points),
        axes=tuple(axes),
        design_names=design_names,
    )


def _axis_names(data: dict[str, Any]) -> set[str]:
    grid = data.get("grid")
    if not isinstance(grid, dict):
        return set()
    return {str(k) for k, v in grid.items() if isinstance(v, dict) and "values" in v}


def _emla_document(study: dict[str, Any]) -> dict[str, Any]:
    emla = study.get("emla")
    file = locate("default" if emla is None else str(emla), "emla")
    document = read_yaml(file)
    if not isinstance(document, dict):
        raise ConfigError(f"{file}: the EMLA file is not a mapping")
    return document


def _check_machine_bounds(path: str, built: Study) -> None:
    """Refuse ``bounds.<chain>…`` of a machine file's study: the machine's chains' bounds are the machine file's.

    A crane file's study gives each chain's ``low`` and ``up`` under ``bounds``; a machine file's
    study does not (:func:`hiab_sim.study.spec.machine_study.machine_study_from_dict`), its decision
    variables' bounds are ``chains.<chain>.variables.<variable>.bounds`` in the machine file. A sweep
    sets the study's keys, one of which is the machine file itself. Any other ``bounds.<key>`` is the
    study's own, set (or refused) like every path.
    """
    steps = parse_path(path)
    chains = list(dict.fromkeys(name.split(".", 1)[0] for name in built.model.design_names))
    if steps[0] != "bounds" or len(steps) < 2 or steps[1] not in chains:
        return
    machine = built.crane_file.label if built.crane_file is not None else built.crane_source
    raise ConfigError(
        f"{path}: a machine file's study has no bounds.{steps[1]}: its decision variables' bounds are in the "
        f"machine file {machine} (chains.<chain>.variables.<variable>.bounds; chains {', '.join(chains)}); to sweep "
        "them, sweep machine over copies of that file with other bounds (paths absolute or relative to the study file)"
    )


def _assign(study: dict[str, Any], emla: dict[str, Any] | None, path: str, value: Any) -> None:
    steps = parse_path(path)
    if steps[0] != "emla":
        set_path(study, path, value, steps)
        return
    assert emla is not None
    rest = steps[1:]
    if not rest or not isinstance(rest[0], str):
        raise ConfigError(f"{path}: expected emla.<actuator>.<key> or emla.pmsm.<key>")
    if rest[0] in (emla.get("actuators") or {}):
        rest = ["actuators", *rest]
    node: Any = emla
    for step in rest[:-1]:
        if not isinstance(node, dict) or step not in node:
            raise ConfigError(f"{path}: the EMLA file has no {step!r} there")
        node = node[step]
    if not isinstance(node, dict) or (rest[-1] not in node and rest[-1] != "pmsm"):
        raise ConfigError(f"{path}: the EMLA file has no key {rest[-1]!r} there")
    set_path(emla, path, value, rest)


def _validate(
    study: dict[str, Any], emla: dict[str, Any] | None, study_file: Path, assignments: list[tuple[str, Any]]
) -> Study:
    """The point's study, built (every value checked); a rejection is one ConfigError naming the assignments."""
    where = ", ".join(f"{p} = {v!r}" for p, v in assignments) or "the base study"
    try:
        if emla is not None:
            emla_set_from_mapping(emla, where="EMLA set")
        # the point's EMLA mapping is checked above (the file is written per point); the study is built with
        # the base study's EMLA file, whose actuators are the machine's
        return study_from_dict(dict(study), study_file)
    except HiabSimError as error:
        raise ConfigError(f"{where}: the study rejects it: {error}") from None

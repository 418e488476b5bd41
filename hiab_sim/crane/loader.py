"""Crane YAML -> validated :class:`~hiab_sim.crane.description.Crane` (presets or files, via hiab_sim.resources).

The loader reads structure and types (:mod:`hiab_sim.yaml_fields`); every range is checked once,
by the dataclasses of :mod:`hiab_sim.crane.description` when they are built, and the default
lengths by :func:`hiab_sim.crane.mechanism.check_lengths`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.crane.description import (
    ChainLengths,
    ClosedChain,
    Crane,
    Matrix3,
    Pose,
    RigidBody,
    Telescope,
    Vector3,
    mat3,
    rot_z,
    vec3,
)
from hiab_sim.crane.mechanism import check_lengths
from hiab_sim.crane.names import (
    ACTUATOR_NAMES,
    BASE,
    CHAIN_NAMES,
    LIFT,
    LIFT_BOOM,
    LIFT_CYLINDER,
    LIFT_ROD,
    TELESCOPE,
    TELESCOPE_ROD,
    TILT,
    TILT_BOOM,
    TILT_CYLINDER,
    TILT_ROD,
)
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.hydraulics.cylinders import hydraulic_cylinders_from_mapping
from hiab_sim.resources import Source, locate
from hiab_sim.yaml_fields import mapping, number, read_yaml

_CHAIN_KEYS = {
    "parent",
    "cylinder_base_pivot",
    "base_axis_angle",
    "joint_offset",
    "L",
    "L1",
    "Lc",
    "Lc0",
    "stroke",
    "joint_range",
}
_TELESCOPE_KEYS = {"parent", "cylinder_frame", "rod_offset", "rod_length", "stroke", "joint_range"}
_TOP_KEYS = {"name", "source", "gravity", "chains", TELESCOPE, "tcp", "bodies"}
_BODY_KEYS = {"frame", "mass", "com", "inertia"}
_POSE_KEYS = {"r", "R"}

#: Source frame -> (link it is rigidly attached to). Frames not listed coincide with a link.
_FRAME_LINKS = {
    "Bc1": BASE,
    "B11": LIFT_BOOM,
    "Bc2": LIFT_BOOM,
    "B31": LIFT_CYLINDER,
    "B41": LIFT_ROD,
    "B12": TILT_BOOM,
    "B32": TILT_CYLINDER,
    "B42": TILT_ROD,
    "P22": TILT_BOOM,
    "B52": TELESCOPE_ROD,
    "P32": TELESCOPE_ROD,
}


def load_crane(source: str | Path | Source = "xs031", relative_to: Source | None = None) -> Crane:
    """Load a crane from a preset name (``xs031``), a YAML file path or a located :class:`Source`.

    A relative path resolves next to ``relative_to`` (the file that names it) when given
    (see :func:`hiab_sim.resources.locate`).

    Raises:
        ConfigError: unknown preset or file, malformed YAML, unknown or missing keys.
        InvalidInputError: a value out of its allowed range (the field is named).

    """
    found = locate(source, "crane", relative_to)
    return crane_from_dict(read_yaml(found), origin=found.label)


def crane_from_dict(data: Any, origin: str = "crane") -> Crane:
    """Build and validate a :class:`Crane` from a parsed YAML mapping."""
    top = mapping(data, origin, _TOP_KEYS | {"hydraulic_cylinders"}, _TOP_KEYS)
    gravity = number(top["gravity"], "gravity")
    chains_data = mapping(top["chains"], "chains", set(CHAIN_NAMES))
    chains = {name: _chain(name, chains_data[name]) for name in CHAIN_NAMES}
    telescope = _telescope(top[TELESCOPE])
    tcp = _pose(top["tcp"], "tcp")
    bodies_data = mapping(top["bodies"], "bodies", None)
    placements = _source_frame_placements(chains[LIFT], chains[TILT], telescope)
    bodies = tuple(_body(name, bodies_data[name], placements) for name in bodies_data)
    crane = Crane(
        name=str(top["name"]),
        source=str(top["source"]),
        gravity=gravity,
        lift=chains[LIFT],
        tilt=chains[TILT],
        telescope=telescope,
        tcp=tcp,
        bodies=bodies,
        hydraulic_cylinders=(
            hydraulic_cylinders_from_mapping(top["hydraulic_cylinders"], ACTUATOR_NAMES)
            if "hydraulic_cylinders" in top
            else None
        ),
    )
    check_lengths(crane, crane.default_lengths)
    return crane


def _vector(value: Any, where: str) -> Vector3:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ConfigError(f"{where}: expected a list of 3 numbers, got {value!r}")
    return vec3([number(v, f"{where}[{i}]") for i, v in enumerate(value)])


def _matrix(value: Any, where: str) -> Matrix3:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ConfigError(f"{where}: expected a 3x3 nested list, got {value!r}")
    return (
        _vector(value[0], f"{where}[0]"),
        _vector(value[1], f"{where}[1]"),
        _vector(value[2], f"{where}[2]"),
    )


def _range(value: Any, where: str) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ConfigError(f"{where}: expected [min, max], got {value!r}")
    return (number(value[0], f"{where}[0]"), number(value[1], f"{where}[1]"))


def _pose(data: Any, where: str) -> Pose:
    pose = mapping(data, where, _POSE_KEYS)
    try:
        return Pose(_vector(pose["r"], f"{where}.r"), _matrix(pose["R"], f"{where}.R"))
    except InvalidInputError as error:  # Pose names its own fields (R); say where it is
        raise InvalidInputError(f"{where}.{error.field}", error.value, error.allowed, error.unit) from None


def _chain(name: str, data: Any) -> ClosedChain:
    chain = mapping(data, f"chains.{name}", _CHAIN_KEYS)
    where = f"{name}"
    return ClosedChain(
        name=name,
        parent=str(chain["parent"]),
        cylinder_base_pivot=_vector(chain["cylinder_base_pivot"], f"{where}.cylinder_base_pivot"),
        base_axis_angle=number(chain["base_axis_angle"], f"{where}.base_axis_angle"),
        joint_offset=number(chain["joint_offset"], f"{where}.joint_offset"),
        L1=number(chain["L1"], f"{where}.L1"),
        default_lengths=ChainLengths(
            L=number(chain["L"], f"{where}.L"),
            Lc0=number(chain["Lc0"], f"{where}.Lc0"),
            Lc=number(chain["Lc"], f"{where}.Lc"),
        ),
        stroke=number(chain["stroke"], f"{where}.stroke"),
        joint_range=_range(chain["joint_range"], f"{where}.joint_range"),
    )


def _telescope(data: Any) -> Telescope:
    tele = mapping(data, TELESCOPE, _TELESCOPE_KEYS)
    return Telescope(
        parent=str(tele["parent"]),
        cylinder_frame=_pose(tele["cylinder_frame"], "telescope.cylinder_frame"),
        rod_offset=number(tele["rod_offset"], "telescope.rod_offset"),
        rod_length=number(tele["rod_length"], "telescope.rod_length"),
        stroke=number(tele["stroke"], "telescope.stroke"),
        joint_range=_range(tele["joint_range"], "telescope.joint_range"),
    )


def _source_frame_placements(lift: ClosedChain, tilt: ClosedChain, telescope: Telescope) -> dict[str, np.ndarray]:
    """4x4 pose of each source frame in the link it belongs to (default lengths)."""
    placements = {name: np.eye(4) for name in _FRAME_LINKS}
    for frame, chain in (("Bc1", lift), ("Bc2", tilt)):
        placements[frame][:3, :3] = rot_z(chain.base_axis_angle)
        placements[frame][:3, 3] = chain.cylinder_base_pivot
    placements["P22"] = telescope.cylinder_frame.matrix
    placements["P32"][0, 3] = telescope.rod_length
    return placements


def _body(name: str, data: Any, placements: dict[str, np.ndarray]) -> RigidBody:
    where = f"bodies.{name}"
    body = mapping(data, where, _BODY_KEYS)
    frame = str(body["frame"])
    if frame not in _FRAME_LINKS:
        raise InvalidInputError(f"{where}.frame", frame, f"must be one of {sorted(_FRAME_LINKS)}")
    mass = number(body["mass"], f"{where}.mass")
    inertia = np.asarray(_matrix(body["inertia"], f"{where}.inertia"))
    placement = placements[frame]
    rotation = placement[:3, :3]
    com = placement[:3, :3] @ np.asarray(_vector(body["com"], f"{where}.com")) + placement[:3, 3]
    return RigidBody(
        name=name,
        link=_FRAME_LINKS[frame],
        mass=mass,
        com=vec3(com),
        inertia=mat3(rotation @ inertia @ rotation.T),
    )

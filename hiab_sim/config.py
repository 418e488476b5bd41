"""Crane description: YAML in, validated frozen dataclasses out (SI units, source frames).

The crane is described in the frames of Petrovic & Mattila (2022): every frame's x-y plane is
the plane of motion, revolute axes are z, and the world frame {W} has y up. Each closed chain
is described with the seed paper's names (``L``, ``L1``, ``Lc``, ``Lc0``), see the preset
``hiab_sim/presets/hiab_xs031.yaml``.

Links (moving rigid bodies) and their frames, shared by both inverse-dynamics paths:

==================  =====================================================================
``base``            {W}, fixed
``lift_boom``       {B11}: origin at the lift boom hinge, x towards the rod-end pivot
``lift_cylinder``   {B31}: origin at the cylinder base pivot, x towards the rod-end pivot
``lift_rod``        {B41}: origin at ``Lc0 + x`` along the cylinder axis; rod end at (Lc, 0, 0)
``tilt_boom``       {B12}, ``tilt_cylinder`` {B32}, ``tilt_rod`` {B42}: likewise
``telescope_rod``   {B52}: at (rod_offset + xt2, 0, 0) in {P22}, axes of {P22}
==================  =====================================================================
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.hydraulics.cylinders import HydraulicCylinders, hydraulic_cylinders_from_mapping
from hiab_sim.yaml_fields import mapping, number, positive, read_yaml

Vector3 = tuple[float, float, float]
Matrix3 = tuple[Vector3, Vector3, Vector3]

PRESET_DIR = Path(__file__).resolve().parent / "presets"
#: Crane presets shipped with the package: name -> YAML file.
CRANE_PRESETS: dict[str, Path] = {"xs031": PRESET_DIR / "hiab_xs031.yaml"}

CHAIN_NAMES = ("lift", "tilt")
LINK_NAMES = (
    "base",
    "lift_boom",
    "lift_cylinder",
    "lift_rod",
    "tilt_boom",
    "tilt_cylinder",
    "tilt_rod",
    "telescope_rod",
)


def rot_z(angle: float) -> np.ndarray:
    """Rotation matrix Rz(angle) about the z axis, angle in [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class Pose:
    """Rigid placement of a frame in its parent: position [m] and rotation matrix."""

    position: Vector3
    rotation: Matrix3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    @property
    def matrix(self) -> np.ndarray:
        """4x4 homogeneous transform parent_T_frame."""
        out = np.eye(4)
        out[:3, :3] = self.rotation
        out[:3, 3] = self.position
        return out


@dataclass(frozen=True)
class ChainLengths:
    """Decision variables xi = [L, Lc0, Lc] of one closed chain (seed eq. before matrix_basis), [m].

    ``L``: cylinder base pivot -> boom hinge; ``Lc0``: piston frame offset inside the cylinder at
    x = 0; ``Lc``: rod length. The retracted pin-to-pin length is x0 = Lc + Lc0.
    """

    L: float
    Lc0: float
    Lc: float

    @property
    def x0(self) -> float:
        """Pin-to-pin length at zero stroke, x0 = Lc + Lc0 [m]."""
        return self.Lc + self.Lc0

    def as_array(self) -> np.ndarray:
        """Return [L, Lc0, Lc]."""
        return np.array([self.L, self.Lc0, self.Lc])


@dataclass(frozen=True)
class LinkLengths:
    """Xi = [xi_lift, xi_tilt]: the link lengths of both closed chains (seed eq. Xi), [m]."""

    lift: ChainLengths
    tilt: ChainLengths

    def __iter__(self) -> Iterator[ChainLengths]:
        return iter((self.lift, self.tilt))

    def as_array(self) -> np.ndarray:
        """Return [L, Lc0, Lc] of the lift chain followed by those of the tilt chain."""
        return np.concatenate([self.lift.as_array(), self.tilt.as_array()])

    @classmethod
    def from_array(cls, values: np.ndarray | list[float]) -> LinkLengths:
        """Build from [L, Lc0, Lc] (lift) + [L, Lc0, Lc] (tilt)."""
        v = [float(a) for a in np.asarray(values, dtype=float).reshape(6)]
        return cls(ChainLengths(*v[:3]), ChainLengths(*v[3:]))


@dataclass(frozen=True)
class ClosedChain:
    """One closed chain: cylinder base pivot, boom hinge, rod-end pivot and a linear actuator.

    The boom hinge and the boom (hence ``L1``) are fixed in the parent link. Changing ``L``
    moves the cylinder base pivot along its fixed direction from the boom hinge (the x axis
    of {Bc}, at ``base_axis_angle`` in the parent), so the boom hinges, the boom geometry and
    the TCP kinematics do not depend on the link lengths.
    """

    name: str
    parent: str
    cylinder_base_pivot: Vector3  # at the default L, in the parent frame [m]
    base_axis_angle: float  # direction base pivot -> boom hinge in the parent [rad]
    joint_offset: float  # theta - boom rotation relative to {Bc} [rad]
    L1: float  # boom hinge -> rod-end pivot [m]
    default_lengths: ChainLengths
    stroke: float  # actuator stroke [m]
    joint_range: tuple[float, float]  # working range of theta [rad]

    @property
    def base_axis(self) -> np.ndarray:
        """Unit vector from the cylinder base pivot to the boom hinge, in the parent frame."""
        return np.array([math.cos(self.base_axis_angle), math.sin(self.base_axis_angle), 0.0])

    @property
    def boom_hinge(self) -> np.ndarray:
        """Position of the boom hinge {B1} in the parent frame [m]; independent of xi."""
        return np.asarray(self.cylinder_base_pivot) + self.default_lengths.L * self.base_axis

    def base_pivot(self, lengths: ChainLengths) -> np.ndarray:
        """Position of the cylinder base pivot {Bc} in the parent frame for these lengths [m]."""
        return self.boom_hinge - lengths.L * self.base_axis


@dataclass(frozen=True)
class Telescope:
    """The telescope: a prismatic joint xt2 along x of the cylinder frame {P22}."""

    parent: str
    cylinder_frame: Pose  # {P22} in the parent link frame
    rod_offset: float  # {B52} at (rod_offset + xt2, 0, 0) in {P22} [m]
    rod_length: float  # {B52} -> end-mass frame {P32} along x [m]
    stroke: float  # [m]
    joint_range: tuple[float, float]  # [m]


@dataclass(frozen=True)
class RigidBody:
    """A rigid body attached to a link: mass [kg], com [m] and inertia about the com [kg m^2].

    ``com`` and ``inertia`` are expressed in the link frame (see the module docstring).
    """

    name: str
    link: str
    mass: float
    com: Vector3
    inertia: Matrix3


@dataclass(frozen=True)
class Crane:
    """A HIAB parallel-serial crane: two closed chains, a telescope, a TCP and rigid bodies."""

    name: str
    source: str
    gravity: float  # [m/s^2], along -y of {W}
    lift: ClosedChain
    tilt: ClosedChain
    telescope: Telescope
    tcp: Pose  # TCP frame {D22} in the end-mass frame {P32}
    bodies: tuple[RigidBody, ...] = field(repr=False)
    hydraulic_cylinders: HydraulicCylinders | None = None  # the cylinders the EMLAs replace, if given

    @property
    def chains(self) -> tuple[ClosedChain, ClosedChain]:
        """The two closed chains, lift first."""
        return (self.lift, self.tilt)

    @property
    def default_lengths(self) -> LinkLengths:
        """The link lengths the crane was built with."""
        return LinkLengths(self.lift.default_lengths, self.tilt.default_lengths)

    @property
    def tcp_in_telescope_rod(self) -> Pose:
        """TCP frame {D22} in the telescope rod frame {B52}."""
        p = np.asarray(self.tcp.position) + np.array([self.telescope.rod_length, 0.0, 0.0])
        return Pose(_vec(p), self.tcp.rotation)

    def bodies_for(self, lengths: LinkLengths) -> tuple[RigidBody, ...]:
        """Rigid bodies for a link-length set: cylinders and rods scaled with their lengths.

        Scaling rule (a uniform slender body of length l): mass and com scale with l, the axial
        moment of inertia (about x) with l, the transverse ones with l^3. The cylinder's length is
        its retracted pin-to-pin length x0 = Lc + Lc0, the rod's is Lc.
        """
        check_positive_lengths(lengths)
        scaled = []
        for body in self.bodies:
            factor = 1.0
            for chain, xi in zip(self.chains, lengths, strict=True):
                default = chain.default_lengths
                if body.link == f"{chain.name}_cylinder":
                    factor = xi.x0 / default.x0
                elif body.link == f"{chain.name}_rod":
                    factor = xi.Lc / default.Lc
            scaled.append(scale_slender_body(body, factor) if factor != 1.0 else body)
        return tuple(scaled)


def scale_slender_body(body: RigidBody, factor: float) -> RigidBody:
    """Scale a slender body along its x axis by ``factor`` (see :meth:`Crane.bodies_for`)."""
    inertia = np.asarray(body.inertia) * factor**3
    inertia[0, 0] = body.inertia[0][0] * factor
    return replace(
        body,
        mass=body.mass * factor,
        com=_vec(np.asarray(body.com) * factor),
        inertia=_mat(inertia),
    )


def check_positive_lengths(lengths: LinkLengths) -> None:
    """Raise :class:`InvalidInputError` unless every L, Lc0, Lc is finite and > 0 (const_g)."""
    for name, xi in zip(CHAIN_NAMES, lengths, strict=True):
        for key in ("L", "Lc0", "Lc"):
            value = getattr(xi, key)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0.0):
                raise InvalidInputError(f"{name}.{key}", value, "must be a finite length > 0", "m")


def check_lengths(crane: Crane, lengths: LinkLengths) -> None:
    """Raise :class:`InvalidInputError` unless every chain can serve its working joint range.

    Checks, per chain: finite, positive L, Lc0, Lc (const_g); the stroke inside [0, Lc]
    (const_j); and over the working range of theta the stroke x inside [0, stroke] and the
    triangle strict, |L - L1| < Lc0 + x + Lc < L + L1 (const_k), so that sin q != 0 and the
    velocity ratios k1..k3 (eq. k1_3) are defined.
    """
    from hiab_sim.crane import mechanism  # local: mechanism imports this module

    check_positive_lengths(lengths)
    for chain, xi in zip(crane.chains, lengths, strict=True):
        if chain.stroke > xi.Lc:
            raise InvalidInputError(
                f"{chain.name}.stroke", chain.stroke, f"must lie in [0, Lc] = [0, {xi.Lc:.6g}] m", "m"
            )
        mechanism.check_joint_samples(chain, xi, np.asarray(chain.joint_range), field=f"{chain.name}.joint_range")


# ---------------------------------------------------------------------------------------------
# YAML loading
# ---------------------------------------------------------------------------------------------

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
_TOP_KEYS = {"name", "source", "gravity", "chains", "telescope", "tcp", "bodies"}
_BODY_KEYS = {"frame", "mass", "com", "inertia"}
_POSE_KEYS = {"r", "R"}

#: Source frame -> (link it is rigidly attached to). Frames not listed coincide with a link.
_FRAME_LINKS = {
    "Bc1": "base",
    "B11": "lift_boom",
    "Bc2": "lift_boom",
    "B31": "lift_cylinder",
    "B41": "lift_rod",
    "B12": "tilt_boom",
    "B32": "tilt_cylinder",
    "B42": "tilt_rod",
    "P22": "tilt_boom",
    "B52": "telescope_rod",
    "P32": "telescope_rod",
}


def load_crane(source: str | Path = "xs031") -> Crane:
    """Load a crane from a preset name (``xs031``) or a YAML file path.

    Raises:
        ConfigError: unknown preset or file, malformed YAML, unknown or missing keys.
        InvalidInputError: a value out of its allowed range (the field is named).

    """
    path = CRANE_PRESETS.get(str(source), Path(source))
    if not path.is_file():
        raise ConfigError(f"crane '{source}' is neither a preset ({', '.join(CRANE_PRESETS)}) nor a readable YAML file")
    return crane_from_dict(read_yaml(path, "crane"), origin=str(path))


def crane_from_dict(data: Any, origin: str = "crane") -> Crane:
    """Build and validate a :class:`Crane` from a parsed YAML mapping."""
    top = mapping(data, origin, _TOP_KEYS | {"hydraulic_cylinders"}, _TOP_KEYS)
    gravity = positive(top["gravity"], "gravity", "m/s^2")
    chains_data = mapping(top["chains"], "chains", set(CHAIN_NAMES))
    chains = {name: _chain(name, chains_data[name]) for name in CHAIN_NAMES}
    telescope = _telescope(top["telescope"])
    tcp = _pose(top["tcp"], "tcp")
    bodies_data = mapping(top["bodies"], "bodies", None)
    placements = _source_frame_placements(chains["lift"], chains["tilt"], telescope)
    bodies = tuple(_body(name, bodies_data[name], placements) for name in bodies_data)
    crane = Crane(
        name=str(top["name"]),
        source=str(top["source"]),
        gravity=gravity,
        lift=chains["lift"],
        tilt=chains["tilt"],
        telescope=telescope,
        tcp=tcp,
        bodies=bodies,
        hydraulic_cylinders=(
            hydraulic_cylinders_from_mapping(top["hydraulic_cylinders"]) if "hydraulic_cylinders" in top else None
        ),
    )
    check_lengths(crane, crane.default_lengths)
    return crane


def _vector(value: Any, where: str) -> Vector3:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ConfigError(f"{where}: expected a list of 3 numbers, got {value!r}")
    return _vec([number(v, f"{where}[{i}]") for i, v in enumerate(value)])


def _matrix(value: Any, where: str) -> Matrix3:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ConfigError(f"{where}: expected a 3x3 nested list, got {value!r}")
    return (
        _vector(value[0], f"{where}[0]"),
        _vector(value[1], f"{where}[1]"),
        _vector(value[2], f"{where}[2]"),
    )


def _range(value: Any, where: str, unit: str) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ConfigError(f"{where}: expected [min, max], got {value!r}")
    low, high = number(value[0], f"{where}[0]"), number(value[1], f"{where}[1]")
    if not low < high:
        raise InvalidInputError(where, f"[{low:.6g}, {high:.6g}]", "must satisfy min < max", unit)
    return (low, high)


def _pose(data: Any, where: str) -> Pose:
    pose = mapping(data, where, _POSE_KEYS)
    rotation = _matrix(pose["R"], f"{where}.R")
    matrix = np.asarray(rotation)
    error = float(np.max(np.abs(matrix @ matrix.T - np.eye(3))))
    if error > 1e-6 or np.linalg.det(matrix) < 0.0:
        raise InvalidInputError(f"{where}.R", f"|R R^T - I| = {error:.3g}", "must be a rotation matrix")
    return Pose(_vector(pose["r"], f"{where}.r"), rotation)


def _chain(name: str, data: Any) -> ClosedChain:
    chain = mapping(data, f"chains.{name}", _CHAIN_KEYS)
    where = f"{name}"
    parent = str(chain["parent"])
    if parent not in LINK_NAMES:
        raise InvalidInputError(f"{where}.parent", parent, f"must be one of {list(LINK_NAMES)}")
    stroke = positive(chain["stroke"], f"{where}.stroke", "m")
    return ClosedChain(
        name=name,
        parent=parent,
        cylinder_base_pivot=_vector(chain["cylinder_base_pivot"], f"{where}.cylinder_base_pivot"),
        base_axis_angle=number(chain["base_axis_angle"], f"{where}.base_axis_angle"),
        joint_offset=number(chain["joint_offset"], f"{where}.joint_offset"),
        L1=positive(chain["L1"], f"{where}.L1", "m"),
        default_lengths=ChainLengths(
            L=positive(chain["L"], f"{where}.L", "m"),
            Lc0=positive(chain["Lc0"], f"{where}.Lc0", "m"),
            Lc=positive(chain["Lc"], f"{where}.Lc", "m"),
        ),
        stroke=stroke,
        joint_range=_range(chain["joint_range"], f"{where}.joint_range", "rad"),
    )


def _telescope(data: Any) -> Telescope:
    tele = mapping(data, "telescope", _TELESCOPE_KEYS)
    stroke = positive(tele["stroke"], "telescope.stroke", "m")
    joint_range = _range(tele["joint_range"], "telescope.joint_range", "m")
    if joint_range[0] < 0.0 or joint_range[1] > stroke:
        raise InvalidInputError(
            "telescope.joint_range",
            f"{list(joint_range)}",
            f"must lie in [0, stroke] = [0, {stroke:.6g}]",
            "m",
        )
    return Telescope(
        parent=str(tele["parent"]),
        cylinder_frame=_pose(tele["cylinder_frame"], "telescope.cylinder_frame"),
        rod_offset=number(tele["rod_offset"], "telescope.rod_offset"),
        rod_length=positive(tele["rod_length"], "telescope.rod_length", "m"),
        stroke=stroke,
        joint_range=joint_range,
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
    mass = positive(body["mass"], f"{where}.mass", "kg")
    inertia = np.asarray(_matrix(body["inertia"], f"{where}.inertia"))
    if np.max(np.abs(inertia - inertia.T)) > 1e-9 or np.min(np.linalg.eigvalsh(inertia)) <= 0.0:
        raise InvalidInputError(f"{where}.inertia", "not symmetric positive definite", "must be SPD", "kg m^2")
    placement = placements[frame]
    rotation = placement[:3, :3]
    com = placement[:3, :3] @ np.asarray(_vector(body["com"], f"{where}.com")) + placement[:3, 3]
    return RigidBody(
        name=name,
        link=_FRAME_LINKS[frame],
        mass=mass,
        com=_vec(com),
        inertia=_mat(rotation @ inertia @ rotation.T),
    )


def _vec(values: Any) -> Vector3:
    a = [float(v) for v in values]
    return (a[0], a[1], a[2])


def _mat(values: Any) -> Matrix3:
    m = np.asarray(values, dtype=float)
    return (_vec(m[0]), _vec(m[1]), _vec(m[2]))

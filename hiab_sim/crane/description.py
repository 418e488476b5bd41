"""Crane description: the frozen dataclasses of a crane (SI units, source frames); YAML in :mod:`hiab_sim.crane.loader`.

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
from dataclasses import dataclass, field, fields, replace

import numpy as np

from hiab_sim.checks import check_range
from hiab_sim.crane.names import CHAIN_NAMES, LINK_NAMES, cylinder_link, rod_link
from hiab_sim.errors import InvalidInputError
from hiab_sim.hydraulics.cylinders import HydraulicSystem
from hiab_sim.machine import parts
from hiab_sim.machine.parts import check_interval, check_rotation, homogeneous, mat3, vec3

Vector3 = tuple[float, float, float]
Matrix3 = tuple[Vector3, Vector3, Vector3]


def rot_z(angle: float) -> np.ndarray:
    """Rotation matrix Rz(angle) about the z axis, angle [rad], as an array (:func:`hiab_sim.machine.parts.rot_z`)."""
    return np.array(parts.rot_z(angle))


@dataclass(frozen=True)
class Pose:
    """Rigid placement of a frame in its parent: position [m] and rotation matrix."""

    position: Vector3
    rotation: Matrix3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    def __post_init__(self) -> None:
        check_rotation(self.rotation)

    @property
    def matrix(self) -> np.ndarray:
        """4x4 homogeneous transform parent_T_frame."""
        return homogeneous(self.position, self.rotation)


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

    @property
    def names(self) -> tuple[str, ...]:
        """``chain.variable`` of each value of :meth:`as_array`, as a machine file's design names them."""
        return tuple(f"{chain}.{f.name}" for chain in CHAIN_NAMES for f in fields(ChainLengths))

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

    def __post_init__(self) -> None:
        name = self.name
        if self.parent not in LINK_NAMES:
            raise InvalidInputError(f"{name}.parent", self.parent, f"must be one of {list(LINK_NAMES)}")
        check_range(f"{name}.base_axis_angle", self.base_axis_angle, unit="rad")
        check_range(f"{name}.joint_offset", self.joint_offset, unit="rad")
        for key in ("L1", "stroke"):
            check_range(f"{name}.{key}", getattr(self, key), 0.0, unit="m", low_open=True)
        for key in ("L", "Lc0", "Lc"):
            check_range(f"{name}.{key}", getattr(self.default_lengths, key), 0.0, unit="m", low_open=True)
        check_interval(f"{name}.joint_range", self.joint_range, "rad")

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

    def __post_init__(self) -> None:
        check_range("telescope.rod_offset", self.rod_offset, unit="m")
        check_range("telescope.rod_length", self.rod_length, 0.0, unit="m", low_open=True)
        check_range("telescope.stroke", self.stroke, 0.0, unit="m", low_open=True)
        low, high = check_interval("telescope.joint_range", self.joint_range, "m")
        if low < 0.0 or high > self.stroke:
            raise InvalidInputError(
                "telescope.joint_range", f"{[low, high]}", f"must lie in [0, stroke] = [0, {self.stroke:.6g}]", "m"
            )


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

    def __post_init__(self) -> None:
        where = f"bodies.{self.name}"
        check_range(f"{where}.mass", self.mass, 0.0, unit="kg", low_open=True)
        inertia = np.asarray(self.inertia, dtype=float)
        if not (np.max(np.abs(inertia - inertia.T)) <= 1e-9 and np.min(np.linalg.eigvalsh(inertia)) > 0.0):
            raise InvalidInputError(f"{where}.inertia", "not symmetric positive definite", "must be SPD", "kg m^2")


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
    hydraulic_cylinders: HydraulicSystem | None = None  # the cylinders the EMLAs replace, if given

    def __post_init__(self) -> None:
        check_range("gravity", self.gravity, 0.0, unit="m/s^2", low_open=True)

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
        return Pose(vec3(p), self.tcp.rotation)

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
                if body.link == cylinder_link(chain.name):
                    factor = xi.x0 / default.x0
                elif body.link == rod_link(chain.name):
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
        com=vec3(np.asarray(body.com) * factor),
        inertia=mat3(inertia),
    )


def check_positive_lengths(lengths: LinkLengths) -> None:
    """Raise :class:`InvalidInputError` unless every L, Lc0, Lc is finite and > 0 (const_g)."""
    for name, xi in zip(CHAIN_NAMES, lengths, strict=True):
        for key in ("L", "Lc0", "Lc"):
            value = getattr(xi, key)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0.0):
                raise InvalidInputError(f"{name}.{key}", value, "must be a finite length > 0", "m")

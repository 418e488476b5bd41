"""Rigid placements and rigid bodies of a machine description (SI units; see :mod:`hiab_sim.machine.description`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from hiab_sim.checks import check_positive, check_range
from hiab_sim.errors import InvalidInputError

Vector3 = tuple[float, float, float]
Matrix3 = tuple[Vector3, Vector3, Vector3]

IDENTITY: Matrix3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def vec3(values: Any) -> Vector3:
    """A 3-vector of floats from any sequence of 3 numbers."""
    a = [float(v) for v in values]
    return (a[0], a[1], a[2])


def mat3(values: Any) -> Matrix3:
    """A 3x3 nested tuple of floats from any 3x3 array."""
    m = np.asarray(values, dtype=float)
    return (vec3(m[0]), vec3(m[1]), vec3(m[2]))


def rot_z(angle: float) -> Matrix3:
    """Rotation matrix Rz(angle) about z, angle [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))


def check_vector(where: str, values: Any, unit: str) -> None:
    """Raise :class:`InvalidInputError` unless every component is a finite number."""
    for i, v in enumerate(values):
        check_range(f"{where}[{i}]", v, unit=unit)


def check_interval(where: str, interval: tuple[float, float], unit: str) -> tuple[float, float]:
    """A finite [min, max] with min < max."""
    low, high = interval
    check_range(f"{where}[0]", low, unit=unit)
    check_range(f"{where}[1]", high, unit=unit)
    if not low < high:
        raise InvalidInputError(where, f"[{low:.6g}, {high:.6g}]", "must satisfy min < max", unit)
    return (low, high)


@dataclass(frozen=True)
class Pose:
    """Rigid placement of a frame in its parent: position [m] and rotation matrix."""

    position: Vector3
    rotation: Matrix3 = IDENTITY

    def __post_init__(self) -> None:
        check_vector("r", self.position, "m")
        matrix = np.asarray(self.rotation, dtype=float)
        if matrix.shape != (3, 3) or not np.all(np.isfinite(matrix)):
            raise InvalidInputError("R", "not a finite 3x3 matrix", "must be a rotation matrix")
        error = float(np.max(np.abs(matrix @ matrix.T - np.eye(3))))
        if not error <= 1e-6 or np.linalg.det(matrix) < 0.0:
            raise InvalidInputError("R", f"|R R^T - I| = {error:.3g}", "must be a rotation matrix")

    @property
    def matrix(self) -> np.ndarray:
        """4x4 homogeneous transform parent_T_frame."""
        out = np.eye(4)
        out[:3, :3] = self.rotation
        out[:3, 3] = self.position
        return out


@dataclass(frozen=True)
class RigidBody:
    """A rigid part: mass [kg], centre of mass [m] and inertia about it [kg m^2], in its frame's axes.

    ``planar_only``: only Izz was given; Ixx = Iyy = Izz/2 (thin plate) so a 3D engine can use it.
    The inertia must be symmetric with eigenvalues > 0 that satisfy the triangle inequality
    (a physical body; MuJoCo's check).
    """

    name: str
    mass: float
    com: Vector3
    inertia: Matrix3
    planar_only: bool = False

    def __post_init__(self) -> None:
        where = self.name
        check_positive(f"{where}.mass", self.mass, "kg")
        check_vector(f"{where}.com", self.com, "m")
        inertia = np.asarray(self.inertia, dtype=float)
        if not np.all(np.isfinite(inertia)):
            raise InvalidInputError(f"{where}.inertia", "NaN or inf", "must be finite", "kg m^2")
        if np.max(np.abs(inertia - inertia.T)) > 1e-9 * max(1.0, float(np.max(np.abs(inertia)))):
            raise InvalidInputError(f"{where}.inertia", "not symmetric", "must be symmetric", "kg m^2")
        eig = np.linalg.eigvalsh(inertia)
        if eig[0] <= 0.0:
            raise InvalidInputError(f"{where}.inertia", f"eigenvalue {eig[0]:.6g}", "must be > 0", "kg m^2")
        if eig[0] + eig[1] < eig[2] * (1.0 - 1e-6):
            raise InvalidInputError(
                f"{where}.inertia",
                f"principal moments {eig[0]:.6g}, {eig[1]:.6g}, {eig[2]:.6g}",
                "must satisfy the triangle inequality I1 + I2 >= I3",
                "kg m^2",
            )

    @property
    def inertia_zz(self) -> float:
        """Izz about the centre of mass in the frame's axes [kg m^2]."""
        return float(self.inertia[2][2])

    def scaled_slender(self, factor: float) -> RigidBody:
        """The body stretched along its x axis by ``factor`` (a uniform slender body).

        Mass and centre of mass scale with the length, the axial moment (xx) with it, every other
        inertia entry with its cube (as :meth:`hiab_sim.crane.description.Crane.bodies_for`).
        """
        inertia = np.asarray(self.inertia) * factor**3
        inertia[0, 0] = self.inertia[0][0] * factor
        return replace(self, mass=self.mass * factor, com=vec3(np.asarray(self.com) * factor), inertia=mat3(inertia))


def combine_bodies(name: str, parts: tuple[RigidBody, ...]) -> RigidBody:
    """One body equal to several rigid parts in the same frame (sum of masses, parallel axes)."""
    mass = sum(p.mass for p in parts)
    com = sum(p.mass * np.asarray(p.com) for p in parts) / mass
    inertia = np.zeros((3, 3))
    for p in parts:
        d = np.asarray(p.com) - com
        inertia += np.asarray(p.inertia) + p.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return RigidBody(name, float(mass), vec3(com), mat3(inertia), all(p.planar_only for p in parts))

"""Actuated closed chains of a machine description: pivots, actuator, four-bar, decision variables.

Conventions in :mod:`hiab_sim.machine.description`. Lengths in m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiab_sim.checks import check_choice, check_non_negative, check_positive
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.parts import RigidBody, Vector3, check_interval, check_vector

CHAIN_KINDS = ("triangle", "linkage", "direct")
VARIABLE_KINDS = ("hinge_distance", "pivot_x", "pivot_y", "piston_offset", "rod_length", "retracted_length")
#: Pivot roles of each chain kind.
PIVOT_ROLES = {"triangle": ("base", "end"), "linkage": ("base", "rocker", "coupler"), "direct": ()}


@dataclass(frozen=True)
class Pivot:
    """A pin of a chain: its role in the chain, the link it is on and its position there [m]."""

    role: str
    link: str
    position: Vector3

    def __post_init__(self) -> None:
        check_vector(f"{self.role}.position", self.position, "m")

    @property
    def xy(self) -> np.ndarray:
        """In-plane coordinates (x, y) in the link frame [m]."""
        return np.asarray(self.position[:2], dtype=float)


@dataclass(frozen=True)
class Actuator:
    """The linear actuator of a chain: stroke, retracted length, its bodies and what drives it.

    Attributes:
        stroke: Usable stroke [m] > 0; the stroke x lies in [0, stroke].
        piston_offset: Lc0 [m] > 0: piston frame offset inside the cylinder at x = 0 (None: direct).
        rod_length: Lc [m] > 0: rod length, piston frame to rod-end pivot (None: direct).
        emla: Name of the EMLA that drives it: its key in the EMLA file, an identifier (letters, digits, _).
        hydraulic_cylinder: Name of the hydraulic cylinder it replaces (in ``hydraulic``), or None.
        cylinder_body: Cylinder (housing) body in the cylinder frame, or None (massless).
        rod_body: Rod body in the rod frame, or None.
        body_scaling: ``slender``: the cylinder body scales with x0 and the rod body with Lc when a
            design changes them (:meth:`RigidBody.scaled_slender`); ``fixed``: they do not.

    """

    stroke: float
    piston_offset: float | None
    rod_length: float | None
    emla: str
    hydraulic_cylinder: str | None = None
    cylinder_body: RigidBody | None = None
    rod_body: RigidBody | None = None
    body_scaling: str = "slender"

    @property
    def retracted_length(self) -> float | None:
        """Pin-to-pin length at zero stroke x0 = Lc0 + Lc [m] (None for a direct actuator)."""
        if self.piston_offset is None or self.rod_length is None:
            return None
        return self.piston_offset + self.rod_length


@dataclass(frozen=True)
class Linkage:
    """The four-bar of a ``linkage`` chain (see the module docstring) and its two bodies."""

    rocker_length: float
    coupler_length: float
    pin_side: int
    rocker_body: RigidBody | None = None
    coupler_body: RigidBody | None = None


@dataclass(frozen=True)
class DecisionVariable:
    """One declared design variable of a chain, with its bounds (see the module docstring).

    ``name`` is unique within its chain (the XS 031's L, Lc0, Lc); :attr:`key` is ``chain.name``.
    ``pivot`` names the pivot role for the pivot kinds, else None.
    """

    chain: str
    name: str
    kind: str
    pivot: str | None
    low: float
    high: float

    def __post_init__(self) -> None:
        where = f"chains.{self.chain}.variables.{self.name}"
        check_choice(f"{where}.kind", self.kind, VARIABLE_KINDS)
        check_interval(f"{where}.bounds", (self.low, self.high), "m")
        needs_pivot = self.kind in ("hinge_distance", "pivot_x", "pivot_y")
        if needs_pivot == (self.pivot is None):
            raise InvalidInputError(
                f"{where}.pivot", str(self.pivot), f"kind {self.kind} {'needs' if needs_pivot else 'takes no'} pivot"
            )

    @property
    def key(self) -> str:
        """Machine-wide name ``chain.name``."""
        return f"{self.chain}.{self.name}"


@dataclass(frozen=True)
class Chain:
    """An actuated closed chain driving one joint (kinds ``triangle``, ``linkage``, ``direct``)."""

    name: str
    kind: str
    joint: str
    actuator: Actuator
    pivots: tuple[Pivot, ...] = ()
    linkage: Linkage | None = None
    variables: tuple[DecisionVariable, ...] = ()

    def __post_init__(self) -> None:
        where = f"chains.{self.name}"
        check_choice(f"{where}.kind", self.kind, CHAIN_KINDS)
        roles = tuple(p.role for p in self.pivots)
        if sorted(roles) != sorted(PIVOT_ROLES[self.kind]):
            raise InvalidInputError(
                f"{where}.pivots", str(list(roles)), f"a {self.kind} needs exactly {list(PIVOT_ROLES[self.kind])}"
            )
        act = self.actuator
        check_positive(f"{where}.actuator.stroke", act.stroke, "m")
        check_choice(f"{where}.actuator.body_scaling", act.body_scaling, ("slender", "fixed"))
        if self.kind == "direct":
            for key in ("piston_offset", "rod_length"):
                if getattr(act, key) is not None:
                    check_non_negative(f"{where}.actuator.{key}", getattr(act, key), "m")
        else:
            for key in ("piston_offset", "rod_length"):
                value = getattr(act, key)
                if value is None:
                    raise InvalidInputError(f"{where}.actuator.{key}", "missing", f"a {self.kind} needs it", "m")
                check_positive(f"{where}.actuator.{key}", value, "m")
        if (self.kind == "linkage") != (self.linkage is not None):
            raise InvalidInputError(f"{where}.linkage", str(self.linkage), "given for and only for a linkage")
        if self.linkage is not None:
            check_positive(f"{where}.linkage.rocker_length", self.linkage.rocker_length, "m")
            check_positive(f"{where}.linkage.coupler_length", self.linkage.coupler_length, "m")
            check_choice(f"{where}.linkage.pin_side", self.linkage.pin_side, (1, -1))
        self._check_variables()

    def _check_variables(self) -> None:
        where = f"chains.{self.name}.variables"
        names = [v.name for v in self.variables]
        if len(set(names)) != len(names):
            raise InvalidInputError(where, str(names), "variable names must be unique within a chain")
        targets: list[tuple[str, str | None]] = []
        for v in self.variables:
            if v.chain != self.name:
                raise InvalidInputError(f"{where}.{v.name}.chain", v.chain, f"must be {self.name}")
            if v.pivot is not None and v.pivot not in PIVOT_ROLES[self.kind]:
                raise InvalidInputError(f"{where}.{v.name}.pivot", v.pivot, f"must be one of {PIVOT_ROLES[self.kind]}")
            if self.kind == "direct" and v.kind in ("piston_offset", "rod_length", "retracted_length"):
                raise InvalidInputError(f"{where}.{v.name}.kind", v.kind, "a direct chain has no retracted length")
            targets.append((v.kind, v.pivot))
        kinds = [k for k, _ in targets]
        if "retracted_length" in kinds and "rod_length" in kinds:
            raise InvalidInputError(where, str(names), "retracted_length and rod_length fix the same length: use one")
        if len(set(targets)) != len(targets):
            raise InvalidInputError(where, str(names), "two variables set the same quantity")
        for pivot in {p for _, p in targets if p is not None}:
            moves = {k for k, p in targets if p == pivot}
            if "hinge_distance" in moves and len(moves) > 1:
                raise InvalidInputError(where, str(names), f"pivot {pivot}: hinge_distance and a coordinate conflict")

    def pivot(self, role: str) -> Pivot:
        """The pivot with this role."""
        for p in self.pivots:
            if p.role == role:
                return p
        raise InvalidInputError(f"chains.{self.name}.pivots", role, f"no pivot {role}")

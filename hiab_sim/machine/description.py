"""Machine description: frozen, validated dataclasses of any planar parallel-serial machine (SI units).

YAML in :mod:`hiab_sim.machine.loader`; loop closure and forward kinematics in
:mod:`hiab_sim.machine.kinematics.closure`. Nothing here spells a machine's names: links, joints, chains and
decision variables are named by the file.

Conventions
-----------
* **Plane.** The plane of motion is the x-y plane of the world frame; y points up, gravity acts
  along -y with magnitude ``gravity`` [m/s^2]. Lengths in m, angles in rad, masses in kg,
  inertias in kg m^2.
* **Links** form a tree with exactly one root (``parent`` None, joint kind ``fixed``, its
  ``joint_frame`` is its pose in the world). Every other link hangs on its parent by one joint:
  its frame is ``parent frame * joint_frame * motion(q)``, where ``joint_frame`` is a fixed
  :class:`Pose` in the parent's frame and ``motion(q)`` is ``Rz(q)`` for a ``revolute`` joint
  (about the joint frame's z axis, which must be the plane normal) or a translation ``q`` along
  the joint frame's x axis for a ``prismatic`` joint (that axis must lie in the plane). ``q`` is
  the joint coordinate [rad or m]; its working range is ``joint_range``.
* **Bodies.** A link carries one or more rigid parts (mass, centre of mass and inertia about it,
  in the link frame); :attr:`Link.mass`, :attr:`Link.com`, :attr:`Link.inertia` combine them.
  A part given with its planar inertia only (``inertia_zz``) gets the thin-plate inertia
  diag(Izz/2, Izz/2, Izz) so a 3D engine can use it; the planar dynamics uses Izz only.
* **Chains.** Each actuated closed chain drives one independent joint (``joint``) with one linear
  actuator whose pin-to-pin length is ``s = x0 + x``, ``x`` in [0, ``stroke``] the stroke and
  ``x0 = piston_offset + rod_length`` the retracted length (the seed's ``x0 = Lc0 + Lc``):

  - ``triangle``: the actuator runs from pivot ``base`` to pivot ``end``; one of them is on the
    parent link of the revolute ``joint``, the other on its child (the seed's lift/tilt chain);
  - ``linkage``: the actuator runs from pivot ``base`` on the parent link of the revolute
    ``joint`` to the pin H of a four-bar: a rocker hinged on that parent link at pivot
    ``rocker`` (|rocker - H| = ``rocker_length``) and a coupler from H to pivot ``coupler`` on
    the driven link (|H - coupler| = ``coupler_length``); H lies on the side ``pin_side``
    (+1: left, -1: right) of the line rocker -> coupler;
  - ``direct``: the actuator is the prismatic ``joint`` itself, ``x = q``.

* **Actuator frames** (for the actuator's own bodies). Cylinder frame: origin at the base pivot,
  x towards the end pivot (H for a linkage). Rod frame: the cylinder frame moved by
  ``piston_offset + x`` along x; the rod end is at (``rod_length``, 0, 0). Rocker frame: origin
  at the rocker pivot, x towards H. Coupler frame: origin at H, x towards the coupler pivot. All
  z axes are the plane normal.
* **Pivots** are points (x, y, z) in their link's frame; the closure uses (x, y), z is the
  out-of-plane offset a 3D model places the pin at. A link carrying a pivot must have its frame's
  z axis along the plane normal.
* **Decision variables** are declared per chain (the seed's xi = [L, Lc0, Lc] for a triangle, or
  any pivot coordinate and the retracted length), each with its bounds; kinds:
  ``hinge_distance`` (a pivot's distance from the chain's hinge, moving it along that line: the
  seed's L), ``pivot_x``/``pivot_y`` (a pivot coordinate in its link frame), ``piston_offset``
  (Lc0), ``rod_length`` (Lc), ``retracted_length`` (x0; the rod length takes x0 - Lc0).
  :meth:`Machine.with_design` returns the machine built with given values.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hiab_sim.checks import check_choice, check_positive
from hiab_sim.errors import InvalidInputError
from hiab_sim.hydraulics.cylinders import HydraulicSystem
from hiab_sim.machine.chains import (
    CHAIN_KINDS,
    PIVOT_ROLES,
    VARIABLE_KINDS,
    Actuator,
    Chain,
    DecisionVariable,
    Linkage,
    Pivot,
)
from hiab_sim.machine.design import variable_value, with_design
from hiab_sim.machine.parts import (
    IDENTITY,
    Matrix3,
    Pose,
    RigidBody,
    Vector3,
    check_interval,
    combine_bodies,
    mat3,
    rot_z,
    vec3,
)

__all__ = [
    "CHAIN_KINDS",
    "IDENTITY",
    "JOINT_KINDS",
    "PIVOT_ROLES",
    "VARIABLE_KINDS",
    "Actuator",
    "Chain",
    "DecisionVariable",
    "HydraulicSystem",
    "Link",
    "Linkage",
    "Machine",
    "Matrix3",
    "Pivot",
    "Pose",
    "RigidBody",
    "Vector3",
    "combine_bodies",
    "mat3",
    "rot_z",
    "vec3",
]

JOINT_KINDS = ("fixed", "revolute", "prismatic")
#: Tolerance of the planarity checks of frames (|cos| of the angle to the plane normal).
PLANAR_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Link:
    """A rigid link of the tree and the joint that carries it (see the module docstring).

    Attributes:
        name: Unique link name.
        parent: Parent link name; None for the root.
        joint: Unique joint name (the root's joint is its fixed attachment to the world).
        joint_kind: ``fixed`` (root only), ``revolute`` or ``prismatic``.
        joint_frame: Pose of the joint frame in the parent's frame (the world for the root).
        joint_range: Working range [min, max] of the joint coordinate [rad or m]; None for fixed.
        parts: Rigid parts on the link (may be empty for a massless root).

    """

    name: str
    parent: str | None
    joint: str
    joint_kind: str
    joint_frame: Pose
    joint_range: tuple[float, float] | None
    parts: tuple[RigidBody, ...] = ()

    def __post_init__(self) -> None:
        where = f"links.{self.name}"
        check_choice(f"{where}.joint_kind", self.joint_kind, JOINT_KINDS)
        if (self.parent is None) != (self.joint_kind == "fixed"):
            raise InvalidInputError(
                f"{where}.joint_kind", self.joint_kind, "the root (no parent) and only the root is fixed"
            )
        if self.joint_kind == "fixed":
            if self.joint_range is not None:
                raise InvalidInputError(f"{where}.joint_range", str(self.joint_range), "a fixed joint has none")
        else:
            if self.joint_range is None:
                raise InvalidInputError(f"{where}.joint_range", "missing", "a moving joint needs [min, max]")
            check_interval(f"{where}.joint_range", self.joint_range, self.unit)
        if not self.parts and self.parent is not None:
            raise InvalidInputError(f"{where}.bodies", "none", "a moving link needs at least one body")

    @property
    def unit(self) -> str:
        """Unit of the joint coordinate: rad (revolute) or m (prismatic)."""
        return "m" if self.joint_kind == "prismatic" else "rad"

    @property
    def body(self) -> RigidBody | None:
        """The link's parts combined into one body (None when it has none)."""
        return combine_bodies(self.name, self.parts) if self.parts else None

    @property
    def mass(self) -> float:
        """Total mass of the link's parts [kg]."""
        return float(sum(p.mass for p in self.parts))


@dataclass(frozen=True)
class Machine:
    """A planar parallel-serial machine: a link tree, actuated closed chains and a TCP.

    Attributes:
        name: Display name.
        source: Where the numbers come from.
        gravity: g [m/s^2] > 0, along -y of the world.
        links: The links, parents before children (the root first).
        chains: The actuated closed chains, in the order of actuator samples.
        tcp_link: The link carrying the TCP.
        tcp: TCP frame in that link's frame.
        hydraulic: The hydraulic baseline, or None.
        workspace: ((x_min, x_max), (y_min, y_max)) the TCP must stay in over the working
            ranges [m] (a cell, a floor), or None.
        realistic_plant: The plant ``hiab-sim simulate --plant realistic`` runs for this machine (a
            shipped plant name or an absolute path, :func:`hiab_sim.env.plant.load_plant`), or None:
            the shipped ``realistic`` (the XS 031's estimates).

    """

    name: str
    source: str
    gravity: float
    links: tuple[Link, ...]
    chains: tuple[Chain, ...]
    tcp_link: str
    tcp: Pose
    hydraulic: HydraulicSystem | None = field(default=None, repr=False)
    workspace: tuple[tuple[float, float], tuple[float, float]] | None = None
    realistic_plant: str | None = None

    def __post_init__(self) -> None:
        check_positive("gravity", self.gravity, "m/s^2")
        if self.workspace is not None:
            check_interval("workspace.x", self.workspace[0], "m")
            check_interval("workspace.y", self.workspace[1], "m")
        self._check_tree()
        self._check_chains()

    # ------------------------------------------------------------------ structure checks
    def _check_tree(self) -> None:
        seen: set[str] = set()
        joints: set[str] = set()
        roots = [link.name for link in self.links if link.parent is None]
        if len(roots) != 1:
            raise InvalidInputError("links", str(roots), "exactly one link must have no parent (the root)")
        for link in self.links:
            where = f"links.{link.name}"
            if link.name in seen:
                raise InvalidInputError(f"{where}", link.name, "duplicate link name")
            if link.joint in joints:
                raise InvalidInputError(f"{where}.joint", link.joint, "duplicate joint name")
            if link.parent is not None and link.parent not in seen:
                known = link.parent in {lk.name for lk in self.links}
                raise InvalidInputError(
                    f"{where}.parent",
                    link.parent,
                    "must be listed before its children" if known else f"unknown link; links: {self.link_names}",
                )
            seen.add(link.name)
            joints.add(link.joint)
        rotations = self.fixed_rotations()
        for link in self.links:
            if link.parent is None:
                continue
            axis = rotations[link.parent] @ np.asarray(link.joint_frame.rotation)
            where = f"links.{link.name}.joint_frame.R"
            if link.joint_kind == "revolute" and abs(axis[2, 2] - 1.0) > PLANAR_TOLERANCE:
                raise InvalidInputError(where, f"z axis {axis[:, 2].round(6).tolist()}", "must be the plane normal")
            if link.joint_kind == "prismatic" and abs(axis[2, 0]) > PLANAR_TOLERANCE:
                raise InvalidInputError(where, f"x axis {axis[:, 0].round(6).tolist()}", "must lie in the plane")
        if self.tcp_link not in seen:
            raise InvalidInputError("tcp.link", self.tcp_link, f"unknown link; links: {self.link_names}")

    def _check_chains(self) -> None:
        names = [c.name for c in self.chains]
        if len(set(names)) != len(names):
            raise InvalidInputError("chains", str(names), "duplicate chain name")
        driven: dict[str, str] = {}
        emla_of: dict[str, str] = {}  # the EMLA names are the study's actuator names: one per chain
        rotations = self.fixed_rotations()
        for chain in self.chains:
            where = f"chains.{chain.name}"
            emla = chain.actuator.emla or chain.name
            if emla in emla_of:
                raise InvalidInputError(
                    f"{where}.actuator.emla",
                    emla,
                    f"already the EMLA of chain {emla_of[emla]}; the EMLA file lists one per chain",
                )
            emla_of[emla] = chain.name
            if chain.joint not in self.joint_names:
                raise InvalidInputError(f"{where}.joint", chain.joint, f"unknown joint; joints: {self.joint_names}")
            if chain.joint in driven:
                raise InvalidInputError(f"{where}.joint", chain.joint, f"already driven by chain {driven[chain.joint]}")
            driven[chain.joint] = chain.name
            link = self.joint_link(chain.joint)
            want = "prismatic" if chain.kind == "direct" else "revolute"
            if link.joint_kind != want:
                raise InvalidInputError(f"{where}.joint", chain.joint, f"a {chain.kind} chain drives a {want} joint")
            for pivot in chain.pivots:
                if pivot.link not in self.link_names:
                    raise InvalidInputError(
                        f"{where}.pivots.{pivot.role}.link", pivot.link, f"unknown link; links: {self.link_names}"
                    )
                if abs(rotations[pivot.link][2, 2] - 1.0) > PLANAR_TOLERANCE:
                    raise InvalidInputError(
                        f"{where}.pivots.{pivot.role}.link", pivot.link, "its frame's z axis must be the plane normal"
                    )
            allowed = self._pivot_links(chain, link)
            for role, links in allowed.items():
                got = chain.pivot(role).link
                if got not in links:
                    raise InvalidInputError(f"{where}.pivots.{role}.link", got, f"must be one of {sorted(links)}")
            if chain.kind == "triangle" and chain.pivot("base").link == chain.pivot("end").link:
                raise InvalidInputError(
                    f"{where}.pivots.end.link", chain.pivot("end").link, "base and end share a link"
                )
            hyd = chain.actuator.hydraulic_cylinder
            if hyd is not None:
                if self.hydraulic is None:
                    raise InvalidInputError(f"{where}.actuator.hydraulic_cylinder", hyd, "the file has no hydraulic")
                self.hydraulic.cylinder(hyd)

    @staticmethod
    def _pivot_links(chain: Chain, link: Link) -> dict[str, set[str]]:
        """Links each pivot role may be on (see the module docstring)."""
        pair = {str(link.parent), link.name}
        if chain.kind == "triangle":
            return {"base": pair, "end": pair}
        if chain.kind == "linkage":
            return {"base": {str(link.parent)}, "rocker": {str(link.parent)}, "coupler": {link.name}}
        return {}

    # ------------------------------------------------------------------ look-ups
    @property
    def link_names(self) -> list[str]:
        """Link names, parents first."""
        return [link.name for link in self.links]

    @property
    def joint_names(self) -> list[str]:
        """Names of the moving joints, in link order (the order of joint samples)."""
        return [link.joint for link in self.links if link.parent is not None]

    @property
    def actuator_names(self) -> list[str]:
        """Chain (actuator) names, in the order of actuator samples."""
        return [c.name for c in self.chains]

    def link(self, name: str) -> Link:
        """The link of this name."""
        for link in self.links:
            if link.name == name:
                return link
        raise InvalidInputError("link", name, f"unknown link; links: {self.link_names}")

    def joint_link(self, joint: str) -> Link:
        """The link that this joint carries."""
        for link in self.links:
            if link.joint == joint:
                return link
        raise InvalidInputError("joint", joint, f"unknown joint; joints: {self.joint_names}")

    def chain(self, name: str) -> Chain:
        """The chain of this name."""
        for c in self.chains:
            if c.name == name:
                return c
        raise InvalidInputError("chain", name, f"unknown chain; chains: {self.actuator_names}")

    def fixed_rotations(self) -> dict[str, np.ndarray]:
        """World rotation of every link frame at zero joint coordinates (3x3).

        Revolute joints turn about the plane normal, so a link's world rotation is
        Rz(sum of its revolute coordinates) times this matrix: it holds every out-of-plane tilt.
        """
        out: dict[str, np.ndarray] = {}
        for link in self.links:
            parent = np.eye(3) if link.parent is None else out[link.parent]
            out[link.name] = parent @ np.asarray(link.joint_frame.rotation)
        return out

    @property
    def independent_joints(self) -> list[str]:
        """Moving joints (all are independent coordinates; chains add actuators, not joints)."""
        return self.joint_names

    def hinge_xy(self, chain: Chain, link: str) -> np.ndarray:
        """In-plane position (x, y) of the chain's hinge in the frame of ``link`` [m].

        ``link`` is the hinge's parent (the hinge is at the joint frame's origin) or its child
        (the hinge is the child frame's origin).
        """
        child = self.joint_link(chain.joint)
        if link == child.name:
            return np.zeros(2)
        return np.asarray(child.joint_frame.position[:2], dtype=float)

    # ------------------------------------------------------------------ decision variables (hiab_sim.machine.design)
    @property
    def decision_variables(self) -> tuple[DecisionVariable, ...]:
        """Every declared decision variable, chain by chain in file order."""
        return tuple(v for c in self.chains for v in c.variables)

    @property
    def variable_keys(self) -> list[str]:
        """``chain.name`` of every decision variable."""
        return [v.key for v in self.decision_variables]

    def design_values(self) -> np.ndarray:
        """Values of :attr:`decision_variables` in this machine [m]."""
        return np.array([variable_value(self, v) for v in self.decision_variables])

    def design_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of :attr:`decision_variables` [m]."""
        variables = self.decision_variables
        return np.array([v.low for v in variables]), np.array([v.high for v in variables])

    def with_design(self, values: Any, *, check_bounds: bool = True) -> Machine:
        """The machine with its decision variables set to ``values`` (:func:`hiab_sim.machine.design.with_design`)."""
        return with_design(self, values, check_bounds=check_bounds)

"""Roles of an imported MJCF's bodies (links, cylinder, rod, rocker, coupler) and the machine tree they give.

Conventions and units in :mod:`hiab_sim.machine.mjcf_import.importer`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from hiab_sim.machine.mjcf_import.frames import Frames
from hiab_sim.machine.mjcf_import.graph import ClosedChain, Mechanism, UnsupportedMJCFError

#: In-plane distance under which two pins are one pin [m].
SAME_PIN = 1e-6


@dataclass
class Role:
    """One closed chain's parts: edges (indices into ``mech.edges``) and groups."""

    kind: str
    block: ClosedChain
    slide: int
    cylinder: int
    rod: int
    base_edge: int
    base_group: int
    end_edge: int
    end_group: int
    driven: int
    rocker_edge: int = -1
    link_edge: int = -1
    coupler_edge: int = -1
    rocker: int = -1
    coupler: int = -1

    @property
    def own_edges(self) -> list[int]:
        """The chain's own joints (every joint of the block but the driven one)."""
        return [k for k in self.block.edges if k != self.driven]

    @property
    def own_groups(self) -> list[int]:
        """Groups that are chain bodies, not machine links."""
        return [g for g in (self.cylinder, self.rod, self.rocker, self.coupler) if g >= 0]


def _other(mech: Mechanism, k: int, g: int) -> int:
    e = mech.edges[k]
    return e.b if e.a == g else e.a


def chain_roles(mech: Mechanism) -> list[Role]:
    """Roles of every closed chain, or one line per chain the machine format cannot hold."""
    roles, problems = [], []
    for block in mech.chains:
        slide = mech.edges[block.slide]
        x, y = slide.a, slide.b
        inside = set(block.edges)
        try:
            for g in (x, y):
                if len([k for k in mech.incident(g) if k not in inside]) or len(mech.incident(g)) != 2:
                    raise ValueError(f"{slide.element}: each actuator body carries exactly its slide and one pin")
            (ex,) = [k for k in mech.incident(x) if k != block.slide]
            (ey,) = [k for k in mech.incident(y) if k != block.slide]
            a, b = _other(mech, ex, x), _other(mech, ey, y)
            rest = [k for k in block.edges if k not in (block.slide, ex, ey)]
            if len(rest) == 1:
                roles.append(Role("triangle", block, block.slide, x, y, ex, a, ey, b, rest[0]))
            else:
                roles.append(_linkage(mech, block, x, y, ex, a, ey, b, rest))
        except ValueError as error:
            problems.append(str(error))
    for role in roles:
        driven = mech.edges[role.driven]
        if driven.kind != "hinge":
            problems.append(f"{driven.element}: the driven joint of a chain must be a hinge joint of the body tree")
        for g in role.own_groups:
            extra = [k for k in mech.incident(g) if k not in role.block.edges]
            if extra:
                problems.append(
                    f"{mech.edges[extra[0]].element}: hangs on a chain body (cylinder, rod, rocker, coupler)"
                )
    if problems:
        raise UnsupportedMJCFError(problems)
    return roles


def _linkage(
    mech: Mechanism, block: ClosedChain, x: int, y: int, ex: int, a: int, ey: int, b: int, rest: list[int]
) -> Role:
    """A four-bar's roles: the rod's pin is the rocker-coupler pin H; the base is on the driven joint's parent.

    H is the four-bar edge at the rod's partner body whose pin coincides with the rod end on that
    body (points fixed on one body keep their distance in any pose, so ``qpos0`` serves).
    """
    data = mujoco.MjData(mech.model)
    data.qpos[:] = mech.model.qpos0
    mujoco.mj_kinematics(mech.model, data)
    frames = Frames(mech, data)
    slide = mech.edges[block.slide].element
    rod_end = frames.edge_point(ey, b)
    ends = lambda k: {mech.edges[k].a, mech.edges[k].b}  # noqa: E731
    at_h = [k for k in rest if b in ends(k) and np.linalg.norm((frames.edge_point(k, b) - rod_end)[:2]) < SAME_PIN]
    if len(at_h) != 1:
        raise ValueError(f"{slide}: a four-bar's actuator must end on the pin of its rocker and coupler")
    n = _other(mech, at_h[0], b)
    if a in (b, n):
        raise ValueError(f"{slide}: the actuator's base and rod end are on the same four-bar pin")
    adjacent = [g for g in (b, n) if any(ends(k) == {a, g} for k in rest)]
    if len(adjacent) != 1:
        raise ValueError(f"{slide}: the actuator's base must be on the body the rocker is pinned to")
    rocker = adjacent[0]
    coupler = n if rocker == b else b
    (c,) = {g for k in rest for g in ends(k)} - {a, rocker, coupler}
    (driven,) = [k for k in rest if ends(k) == {a, c}]
    (rocker_edge,) = [k for k in rest if ends(k) == {a, rocker}]
    (coupler_edge,) = [k for k in rest if ends(k) == {coupler, c}]
    if mech.edges[driven].a != a:
        raise ValueError(f"{slide}: a four-bar's actuator base and rocker must be on the driven joint's parent")
    return Role(
        "linkage", block, block.slide, x, y, ex, a, ey, b, driven, rocker_edge, at_h[0], coupler_edge, rocker, coupler
    )


def in_plane_angle(v: np.ndarray) -> float:
    """Angle of an in-plane vector's (x, y) [rad]."""
    return math.atan2(float(v[1]), float(v[0]))

"""Mounting space of a machine file's pivots: polygons and clearances as rows of the decision variables [m].

The machine form of a study's ``mounting`` section (the crane file's is
:mod:`hiab_sim.crane.mounting`, for its two base pivots by chain name)::

    mounting:
      <actuator>:                       # a chain of the machine file, by name
        <pivot>: [[x, y], [x, y], ...]  # a pivot role of that chain (base, end, rocker, coupler), its link's frame, m
      clearance: 0.05                   # m, centre to centre
      samples: 91                       # joint samples over the working range for the swept link

Pivot positions. A pivot that a decision variable moves (kinds ``hinge_distance``, ``pivot_x``,
``pivot_y``, :mod:`hiab_sim.machine.design`) is affine in the variables, in its link's frame:

    p(v) = p_0 + sum_k u_k (v_k - v_k0),        dp/dv_k = u_k,

u_k the unit x or y axis for a coordinate and the unit vector from the chain's hinge through the
pivot for a hinge distance (:func:`hiab_sim.machine.kinematics.design_partials.pivot_direction`).
Every row here is exact to first order; a polygon row is even linear in v, so the buildable
design's first-order tolerance margin is exact on it (:mod:`hiab_sim.study.analysis.buildable`).

Rows, for every pivot a decision variable moves (the "moved pivots"), in chain and pivot order:

* **Polygon** (where the study gives one for that pivot): the signed distance to each edge of a
  convex counter-clockwise polygon in the pivot's link frame, >= 0 inside
  (:func:`hiab_sim.machine.mounting_geometry.edge_rows`). A polygon on a pivot no variable moves
  would be a constant row: refused when the study loads.
* **Pins on the same link**: |p - c| - clearance for every other pin c on the pivot's link: the
  link's own hinge (its joint frame's origin, if it has a parent), the hinges of its child links,
  and every other chain pivot on it (a moved one with its own dc/dv). The hinge of the link the
  chain drives is left to the swept-link row below, which holds it already (two equal rows would
  make the active set degenerate).
* **Swept link** (a pivot on the parent P of the link D its chain's revolute joint turns): the
  smallest distance, minus the clearance, from p to D's centre line over D's working range: the
  polyline from D's hinge through D's points (chain pivots on D and the joint frames of D's
  children, a slide's too) in order of distance from the hinge, turned by the joint at ``samples`` points of its range
  (c = h + Rz(phi + q) c_D in P, :func:`hiab_sim.machine.kinematics.closure.chain_geometry`). A
  pin of D that a variable moves moves the line: the closest point c = a + t (b - a) carries
  dc/dv = (1 - t) da/dv + t db/dv (t fixed to first order).

Pins are points: an eye's size is the clearance, a bracket's outline is the polygon. Not modelled
(choices): the rocker and coupler of a four-bar sweeping past a pivot, a link's outline beyond its
centre line, pivots on links other than the chain's hinge's parent against a swept link. Names of
rows: ``mounting.<chain> <pivot> pivot inside edge <i>``, ``... clear of the <pin>``,
``... clear of the <link> over its working range``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.machine import mounting_geometry as geometry
from hiab_sim.machine.chains import Chain
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import designed_chain
from hiab_sim.machine.kinematics.closure import chain_geometry
from hiab_sim.machine.kinematics.design_partials import pivot_direction
from hiab_sim.machine.mounting_geometry import Margins, Polygon
from hiab_sim.yaml_fields import mapping, positive

#: Kinds of decision variable that move a pivot.
PIVOT_KINDS = ("hinge_distance", "pivot_x", "pivot_y")
#: Keys of the section beside the actuators' names.
SETTINGS = ("clearance", "samples")


#: Where one pivot may sit: (chain, pivot role, a convex counter-clockwise polygon (x, y) [m] in its link's frame).
PivotPolygon = tuple[str, str, Polygon]


@dataclass(frozen=True)
class MachineMountingSpace:
    """A machine file's mounting space: polygons of moved pivots, a pin clearance [m] and the swept-link samples."""

    polygons: tuple[PivotPolygon, ...] = ()
    clearance: float = geometry.DEFAULT_CLEARANCE
    samples: int = geometry.DEFAULT_SAMPLES

    def __post_init__(self) -> None:
        for chain, pivot, vertices in self.polygons:
            geometry.check_polygon(f"mounting.{chain}.{pivot}", vertices)
        geometry.check_clearance_and_samples("mounting", self.clearance, self.samples)

    def polygon(self, chain: str, pivot: str) -> Polygon | None:
        """The polygon of a chain's pivot, or None."""
        for name, role, vertices in self.polygons:
            if (name, role) == (chain, pivot):
                return vertices
        return None

    @classmethod
    def from_mapping(cls, data: Any, machine: Machine, where: str = "mounting") -> MachineMountingSpace:
        """Build from a machine study's ``mounting`` mapping (module docstring), checked against ``machine``."""
        node = mapping(data, where, set(machine.actuator_names) | set(SETTINGS), required=set())
        moved = moved_pivots(machine)
        polygons = []
        for name in machine.actuator_names:
            if name not in node:
                continue
            chain = machine.chain(name)
            roles = {p.role for p in chain.pivots}
            given = mapping(node[name], f"{where}.{name}", roles, required=set())
            for role, vertices in given.items():
                if (name, role) not in moved:
                    raise InvalidInputError(
                        f"{where}.{name}.{role}",
                        "a fixed pivot",
                        "a polygon needs a pivot that a decision variable moves (kind "
                        + ", ".join(PIVOT_KINDS)
                        + f"); moved pivots: {', '.join(f'{c}.{r}' for c, r in moved) or 'none'}",
                    )
                polygon = geometry.read_polygon(vertices, f"{where}.{name}.{role}")
                if polygon is None:  # an empty key: YAML's null
                    raise ConfigError(f"{where}.{name}.{role}: expected a list of [x, y] vertices, got None")
                polygons.append((name, role, polygon))
        clearance = positive(node.get("clearance", geometry.DEFAULT_CLEARANCE), f"{where}.clearance", "m")
        return cls(tuple(polygons), clearance, geometry.read_samples(node.get("samples"), f"{where}.samples"))


def moved_pivots(machine: Machine) -> list[tuple[str, str]]:
    """(chain, pivot role) of every pivot a decision variable moves, in chain and pivot order."""
    out = []
    for chain in machine.chains:
        moved = {v.pivot for v in chain.variables if v.kind in PIVOT_KINDS}
        out += [(chain.name, p.role) for p in chain.pivots if p.role in moved]
    return out


@dataclass(frozen=True)
class _Pin:
    """A point on a link: its label, (x, y) in the link frame [m], d(x, y)/dv (2, n) and whether it is a pin."""

    label: str
    xy: Array
    dxy: Array
    is_pin: bool = True


def _pivot_pins(machine: Machine, chains: dict[str, Chain], link: str, n: int) -> list[tuple[str, str, _Pin]]:
    """(chain, role, pin) of every chain pivot on ``link`` at the design ``chains`` (chain name -> designed chain)."""
    variables = machine.decision_variables
    out = []
    for chain in machine.chains:
        for pivot in chains[chain.name].pivots:
            if pivot.link != link:
                continue
            dxy = np.zeros((2, n))
            for k, v in enumerate(variables):
                if v.chain == chain.name and v.pivot == pivot.role and v.kind in PIVOT_KINDS:
                    dxy[:, k] = pivot_direction(machine, chain, v)
            out.append((chain.name, pivot.role, _Pin(f"{chain.name} {pivot.role} pivot", pivot.xy, dxy)))
    return out


def _joint_points(machine: Machine, link: str, n: int) -> list[tuple[str, _Pin]]:
    """(joint, point) of the joints on ``link``: its own (at its origin) and its children's (their joint frames).

    A revolute joint's point is a hinge (a pin); a prismatic child's is where its slide starts, a
    point of the link's centre line but no pin.
    """
    own = machine.link(link)
    out = []
    if own.parent is not None and own.joint_kind == "revolute":
        out.append((own.joint, _Pin(f"{own.joint} hinge", np.zeros(2), np.zeros((2, n)))))
    for child in machine.links:
        if child.parent == link:
            xy = np.asarray(child.joint_frame.position[:2], dtype=float)
            hinge = child.joint_kind == "revolute"
            label = f"{child.joint} {'hinge' if hinge else 'joint frame'}"
            out.append((child.joint, _Pin(label, xy, np.zeros((2, n)), is_pin=hinge)))
    return out


def _hinges(machine: Machine, link: str, n: int) -> list[tuple[str, _Pin]]:
    """(joint, pin) of the revolute joints' hinges on ``link`` (:func:`_joint_points` less the slides)."""
    return [(joint, pin) for joint, pin in _joint_points(machine, link, n) if pin.is_pin]


def _centre_line(machine: Machine, chains: dict[str, Chain], driven: str, n: int) -> list[_Pin]:
    """The driven link's centre line in its frame: its hinge, then its other points by distance from the hinge."""
    joint = machine.link(driven).joint
    points = _joint_points(machine, driven, n)
    others = [pin for _, _, pin in _pivot_pins(machine, chains, driven, n)] + [p for j, p in points if j != joint]
    return [p for j, p in points if j == joint] + sorted(others, key=lambda pin: float(np.hypot(*pin.xy)))


def machine_mounting_margins(space: MachineMountingSpace, machine: Machine, values: Any) -> Margins:
    """Every mounting row (module docstring) at decision-variable values ``values`` [m], with exact dg/dv.

    ``machine`` is the file's machine (its decision variables in order); the values need not lie in
    its bounds (the NLP holds them).
    """
    v = np.asarray(values, dtype=float).reshape(-1)
    n = len(machine.decision_variables)
    chains = {c.name: designed_chain(machine, c, v, bodies=False) for c in machine.chains}
    polygon_part: tuple[list[str], list[float], list[Array]] = ([], [], [])
    clearance_part: tuple[list[str], list[float], list[Array]] = ([], [], [])
    for name, role in moved_pivots(machine):
        chain = machine.chain(name)
        pivot = chains[name].pivot(role)
        on_link = _pivot_pins(machine, chains, pivot.link, n)
        me = next(pin for c, r, pin in on_link if (c, r) == (name, role))
        where = f"mounting.{name} {role} pivot"
        polygon = space.polygon(name, role)
        if polygon is not None:
            edge_values, edge_jacobian = geometry.edge_rows(polygon, me.xy, me.dxy)
            polygon_part[0].extend(f"{where} inside edge {i}" for i in range(len(polygon)))
            polygon_part[1].extend(edge_values)
            polygon_part[2].extend(edge_jacobian)
        driven = machine.joint_link(chain.joint)
        swept = chain.kind != "direct" and driven.joint_kind == "revolute" and driven.parent == pivot.link
        pins = [pin for joint, pin in _hinges(machine, pivot.link, n) if not (swept and joint == chain.joint)]
        pins += [pin for c, r, pin in on_link if (c, r) != (name, role)]
        for pin in pins:
            d, grad = geometry.point_distance(me.xy, pin.xy)
            clearance_part[0].append(f"{where} clear of the {pin.label}")
            clearance_part[1].append(d - space.clearance)
            clearance_part[2].append(grad @ (me.dxy - pin.dxy))
        if swept:
            d, row = _swept_clearance(machine, chains, chain, me, space.samples, n)
            clearance_part[0].append(f"{where} clear of the {driven.name} over its working range")
            clearance_part[1].append(d - space.clearance)
            clearance_part[2].append(row)
    return Margins.stacked([geometry.margins(*polygon_part, n), geometry.margins(*clearance_part, n)], n)


def _swept_clearance(
    machine: Machine, chains: dict[str, Chain], chain: Chain, me: _Pin, samples: int, n: int
) -> tuple[float, Array]:
    """Smallest distance [m] of pin ``me`` from the swept centre line of the link ``chain`` turns, and d/dv (n,)."""
    driven = machine.joint_link(chain.joint)
    geo = chain_geometry(machine, chain)
    line = _centre_line(machine, chains, driven.name, n)
    local = np.array([pin.xy for pin in line])  # (P, 2) in the driven frame
    dlocal = np.array([pin.dxy for pin in line])  # (P, 2, n)
    if driven.joint_range is None:
        raise InvalidInputError(f"links.{driven.name}.joint_range", "none", "the swept clearance needs a range")
    angle = geo.phi + np.linspace(*driven.joint_range, samples)  # (S,)
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    rotation = np.concatenate([np.concatenate([c, -s], axis=2), np.concatenate([s, c], axis=2)], axis=1)  # (S, 2, 2)
    points = geo.hinge + np.einsum("sij,pj->spi", rotation, local)  # (S, P, 2)
    d, grad, (k, i), t = geometry.polyline_distance(me.xy, points)
    dclosest = rotation[k] @ ((1.0 - t) * dlocal[i] + t * dlocal[i + 1])  # (2, n)
    return d, grad @ (me.dxy - dclosest)


__all__ = ["MachineMountingSpace", "PivotPolygon", "machine_mounting_margins", "moved_pivots"]

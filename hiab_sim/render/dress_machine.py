"""The dress of a machine file's model, from its description: what :func:`~hiab_sim.render.dress.dress_scene` draws.

The model is :mod:`hiab_sim.machine.dynamics.mjcf_build`'s (one capsule from each body's origin to
every point it carries; bodies named after the description's links and ``<chain>.cylinder``,
``.rod``, ``.rocker``, ``.coupler``). Every size comes from the description, by the rule stated
next to it where the file gives none:

* **Links** are square steel box sections whose depth h follows from the link's mass m [kg] and
  reach l [m] (the farthest point it carries from its joint): with a wall t = h / :data:`SLENDERNESS`,
  the mass per length is m / l = rho (h^2 - (h - 2 t)^2) = 0.19 rho h^2, so h = sqrt(m / (0.19 rho l))
  (:func:`section_depth`; the eXact's 227 kg, 2.05 m boom: 0.27 m; a tool's parts drawn as blocks
  are not counted). The section runs from the link's joint to each child link's joint (and the
  TCP), straight or, when the centre of mass lies off that chord, bent through the knee
  (:func:`spine`); lugs of :data:`LUG_DEPTH` times the depth run from it to every other point the
  link carries (:func:`link_plates`). The model's capsules of the link are not drawn. Rockers and
  couplers are bars of the same rule from their own bodies; a massless root (a slewing chassis)
  takes :data:`ROOT_FACTOR` times the deepest link.
* **Actuators**: a barrel of the named hydraulic cylinder's bore plus the crane's wall and a rod of
  its rod diameter (the crane's rule, :data:`~hiab_sim.render.dress.BARREL_WALL_M`); without
  cylinder data, the radius of a uniform solid cylinder with the actuator body's mass and axial
  inertia, r = sqrt(2 I_xx / m); without a body, the model's capsule.
* **Tool**: a TCP on a prismatic link (a telescope) gets the crane's hook, the payload hanging
  under it, and the link's parts other than its own drawn as blocks (an end mass); a TCP on a
  revolute link (a tool the machine turns: a bucket) is drawn as plates of :data:`TOOL_WIDTH_M`
  closing the outline from its pivots to the TCP, the payload (of :data:`SOIL_DENSITY`) sitting in
  it at the link's centre of mass.
* **Base and ground**: a base block (:data:`BASE_SIZE_M`) under the root link, from the ground to the
  root's lowest point, reaching behind it as the crane's truck bed; the ground as a slab whose top
  is the task's ground level when given (the soil the tool cuts: the slab lies behind the plane of
  motion, a section through the soil, so the tool shows below the surface) or else the model's
  floor (under the whole machine). The model's own floor plane is not drawn.
"""

from __future__ import annotations

import itertools

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.machine.description import Chain, Machine
from hiab_sim.machine.dynamics.tree import MachineTree, machine_tree
from hiab_sim.render.dress import (
    BARREL_WALL_M,
    BED_RGBA,
    PIN_OVERHANG_M,
    STEEL_DENSITY,
    Block,
    MachineDress,
    Plate,
    Slab,
    floor_height,
    materials,
    model_pins,
    name_of,
)

#: Depth over wall thickness of the drawn box sections: a choice, the order of welded boom plates (h/t 15-30).
SLENDERNESS = 20.0
#: Lugs (a link's capsules to its pivots) are this fraction of the link's depth: a choice, so the link reads first.
LUG_DEPTH = 0.5
#: A massless root's section over the deepest link's: a choice, as the crane's column over its booms (0.18 / 0.12).
ROOT_FACTOR = 1.5
#: A turned tool's width across the plane [m]: a choice, the order of a 1.5-2 t excavator's bucket
#: (optimize/exact_digging.yaml's cutting edge, 0.40 m); its plate thickness [m]: a choice.
TOOL_WIDTH_M = 0.40
TOOL_PLATE_M = 0.03
#: Drawn density of a payload in a turned tool [kg/m^3]: the shipped medium clay's (soil_medium_clay.yaml).
SOIL_DENSITY = 1900.0
#: Base block under the root: (length, width) [m], a choice of a compact machine's footprint (the order
#: of a mini excavator's 1.6-2.0 m track length and of the crane's 2.2 m truck bed); its least height [m].
BASE_SIZE_M = (2.0, 1.0)
BASE_MIN_HEIGHT_M = 0.16
#: Ground slab: thickness [m], depth behind the plane of motion [m], and margin past the machine's reach [m].
GROUND_THICKNESS_M = 0.5
GROUND_DEPTH_M = 3.0
GROUND_MARGIN_M = 1.0
GROUND_RGBA = (0.62, 0.56, 0.47, 1.0)  # earth, lighter than the base's grey and the payload's brown
#: Two capsule ends closer than this are one point [m].
POINT_TOLERANCE_M = 1e-6


def section_depth(mass: float, length: float) -> float:
    """Depth h [m] of a square steel box, wall h / SLENDERNESS, of ``mass`` [kg] over ``length`` [m] (module text)."""
    fill = 1.0 - (1.0 - 2.0 / SLENDERNESS) ** 2
    return float(np.sqrt(mass / (fill * STEEL_DENSITY * length)))


def _ends(model: mujoco.MjModel, body: int, material: int) -> list[tuple[int, Array]]:
    """The geoms of ``material`` on ``body`` and each capsule's far end in the body frame [m] (capsules start at 0)."""
    return [
        (g, 2.0 * np.array(model.geom_pos[g]))
        for g in range(model.ngeom)
        if int(model.geom_bodyid[g]) == body and int(model.geom_matid[g]) == material
    ]


def _reach(points: list[Array]) -> float:
    return max((float(np.linalg.norm(p)) for p in points), default=0.0)


def _main_points(tree: MachineTree, k: int) -> list[Array]:
    """Points of tree body ``k`` its spine runs to: its child links' joints and, on the tool, the TCP."""
    points = [b.position for b in tree.bodies if b.parent == k and b.chain is None]
    if k == tree.tcp_body:
        points.append(np.asarray(tree.tcp.position, dtype=float))
    return [p for p in points if np.linalg.norm(p) > POINT_TOLERANCE_M]


def _carried(tree: MachineTree, k: int) -> list[Array]:
    """Every point of tree body ``k`` something hangs on: child bodies' joints, loop pins, the TCP [m]."""
    points = [b.position for b in tree.bodies if b.parent == k] + [lp.point_b for lp in tree.loops if lp.body_b == k]
    if k == tree.tcp_body:
        points.append(np.asarray(tree.tcp.position, dtype=float))
    return [np.asarray(p, dtype=float) for p in points if np.linalg.norm(p) > POINT_TOLERANCE_M]


def spine(main: Array, carried: list[Array], com: Array, depth: float) -> list[Array]:
    """The polyline [m] a link's box section follows from its joint (the origin) to ``main``.

    The chord, unless the centre of mass ``com`` lies off it by more than a quarter of the section
    ``depth``: then the link is bent (an excavator's boom) through its knee, the carried point
    farthest from the chord on the centre of mass's side among those that project inside it.
    """
    chord = np.asarray(main[:2], dtype=float)
    length = float(np.linalg.norm(chord))
    normal = np.array([-chord[1], chord[0]]) / length
    offset = float(np.asarray(com[:2]) @ normal)
    origin = np.zeros(3)
    if abs(offset) <= 0.25 * depth:
        return [origin, np.asarray(main, dtype=float)]
    best, knee = 0.25 * depth, None
    for point in carried:
        along, side = float(point[:2] @ chord) / length**2, float(point[:2] @ normal) * np.sign(offset)
        if 0.0 < along < 1.0 and side > best:
            best, knee = side, point
    return [origin, np.asarray(main, dtype=float)] if knee is None else [origin, knee, np.asarray(main, dtype=float)]


def _nearest_on(polyline: list[Array], point: Array) -> Array:
    """The point of ``polyline`` nearest to ``point`` [m]."""
    best = polyline[0]
    for a, b in itertools.pairwise(polyline):
        ab = b - a
        t = float(np.clip((point - a) @ ab / max(float(ab @ ab), 1e-12), 0.0, 1.0))
        candidate = a + t * ab
        if np.linalg.norm(point - candidate) < np.linalg.norm(point - best):
            best = candidate
    return best


def link_plates(tree: MachineTree, k: int, body: int, section: tuple[float, float], lug: float) -> list[Plate]:
    """A link's box sections: along its spines (``section`` = depth, width [m]) and lugs to the other points it carries.

    A lug runs from the nearest point of the spines to the point, ``lug`` times the depth.
    """
    depth, width = section
    link = tree.bodies[k]
    com = np.zeros(3) if link.inertia is None else np.asarray(link.inertia.com, dtype=float)
    carried = _carried(tree, k)
    lines = [spine(p, carried, com, depth) for p in _main_points(tree, k)]
    plates = [Plate(body, a, b, depth, width) for line in lines for a, b in itertools.pairwise(line)]
    vertices = [v for line in lines for v in line] or [np.zeros(3)]
    for point in carried:
        if min(float(np.linalg.norm(point - v)) for v in vertices) <= POINT_TOLERANCE_M:
            continue
        nearest = [_nearest_on(line, point) for line in lines] or [np.zeros(3)]
        start = min(nearest, key=lambda q: float(np.linalg.norm(point - q)))
        plates.append(Plate(body, start, point, lug * depth, width))
    return plates


def _radii(machine: Machine, chain: Chain, capsule: tuple[float, float]) -> tuple[float, float]:
    """Barrel and rod radius [m] of a chain's actuator (module docstring's rule)."""
    act = chain.actuator
    if act.hydraulic_cylinder is not None and machine.hydraulic is not None:
        data = machine.hydraulic.cylinder(act.hydraulic_cylinder)
        return 0.5 * data.bore + BARREL_WALL_M, 0.5 * data.rod
    radii = list(capsule)
    for k, body in enumerate((act.cylinder_body, act.rod_body)):
        if body is not None:
            radii[k] = float(np.sqrt(2.0 * np.asarray(body.inertia)[0, 0] / body.mass))
    return radii[0], radii[1]


def machine_file_dress(model: mujoco.MjModel, machine: Machine, ground: float | None = None) -> MachineDress:
    """The dress of ``model``, the machine file's MJCF of ``machine`` (at the design drawn), from its description.

    ``ground``: the task's ground level [m] (the description's world y = MuJoCo z), or None (the
    model's floor). See the module docstring for every rule.
    """
    tree = machine_tree(machine)
    found = materials(model)
    body_id = {name_of(model, mujoco.mjtObj.mjOBJ_BODY, b): b for b in range(model.nbody)}
    kind: dict[int, str] = {}
    section: dict[int, tuple[float, float]] = {}
    radius: dict[int, float] = {}
    tool_turns = machine.link(machine.tcp_link).joint_kind == "revolute"
    tool_link = machine.link(machine.tcp_link)
    carried = () if tool_turns else tuple(p for p in tool_link.parts if p.name != tool_link.name)  # drawn as blocks
    depth: dict[str, float] = {}
    for k, body in enumerate(tree.bodies):
        if body.inertia is None or (body.chain is not None and body.name.endswith((".cylinder", ".rod"))):
            continue
        ends = [end for _, end in _ends(model, body_id[body.name], found["hiab_red"])]
        length = _reach(_main_points(tree, k) or ends)
        own = body.inertia.mass - sum(p.mass for p in carried) if body.name == tool_link.name else body.inertia.mass
        if length > POINT_TOLERANCE_M:
            depth[body.name] = section_depth(own, length)
    deepest = max(depth.values(), default=0.1)
    hidden: set[int] = set(int(g) for g in np.nonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)[0])
    plates: list[Plate] = []
    for k, body in enumerate(tree.bodies):
        b = body_id[body.name]
        h = depth.get(body.name, ROOT_FACTOR * deepest)
        capsules = _ends(model, b, found["hiab_red"])
        if body.chain is not None:  # a rocker or coupler: a bar of its own section
            for g, _ in capsules:
                kind[g], section[g] = "structure", (h, h)
            continue
        hidden.update(g for g, _ in capsules)
        if k == tree.tcp_body and tool_turns:
            outline = link_plates(tree, k, b, (TOOL_PLATE_M, TOOL_WIDTH_M), 1.0)
            tcp = np.asarray(tree.tcp.position, dtype=float)
            closing = [Plate(b, p.end, tcp, TOOL_PLATE_M, TOOL_WIDTH_M) for p in outline if p.end is not tcp]
            plates.extend([p for p in outline + closing if np.linalg.norm(p.end - p.start) > POINT_TOLERANCE_M])
        else:
            plates.extend(link_plates(tree, k, b, (h, h), LUG_DEPTH))
        for g, _ in _ends(model, b, found["cylinder"]):  # a slide's guide: an extension inside its link
            kind[g], section[g] = "structure", (0.75 * h, 0.75 * h)
    for chain in machine.chains:
        if chain.kind == "direct":
            continue
        cylinder, rod = body_id[f"{chain.name}.cylinder"], body_id[f"{chain.name}.rod"]
        barrels, rods = _ends(model, cylinder, found["cylinder"]), _ends(model, rod, found["rod"])
        capsule = tuple(float(model.geom_size[parts[0][0], 0]) if parts else 0.0 for parts in (barrels, rods))
        barrel_r, rod_r = _radii(machine, chain, (capsule[0], capsule[1]))
        for g, _ in barrels:
            kind[g], radius[g] = "barrel", barrel_r
        for g, _ in rods:
            kind[g], radius[g] = "rod", rod_r
    pins, pin_sites = model_pins(model)
    widths = [p.width for p in plates] + [w for _, w in section.values()]
    tcp_site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tcp")
    tool = body_id[machine.tcp_link]
    anchor = None
    if tool_turns and tool_link.body is not None:
        anchor = (tool, np.asarray(tool_link.body.com, dtype=float))
    blocks = tuple(
        Block(tool, np.asarray(p.com, dtype=float), float((p.mass / STEEL_DENSITY) ** (1.0 / 3.0))) for p in carried
    )
    pin_length = max(widths, default=0.1) + 2.0 * PIN_OVERHANG_M
    return MachineDress(
        kind, section, radius, pins, pin_sites, pin_length, blocks, tcp_site,
        hook=not tool_turns, payload_anchor=anchor,
        payload_density=SOIL_DENSITY if tool_turns else STEEL_DENSITY,
        plates=tuple(plates), slabs=_slabs(model, tree, body_id, ground, pin_length, deepest), hidden=frozenset(hidden),
    )  # fmt: skip


def _slabs(
    model: mujoco.MjModel,
    tree: MachineTree,
    body_id: dict[str, int],
    ground: float | None,
    pin_length: float,
    deepest: float,
) -> tuple[Slab, ...]:
    """The base block under the root and the ground slab (module docstring), in the MuJoCo world [m]."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    root = body_id[tree.bodies[0].name]
    rotation = data.xmat[root].reshape(3, 3)
    origin = np.array(data.xpos[root])
    carried = [b.position for b in tree.bodies if b.parent == 0] + [lp.point_b for lp in tree.loops if lp.body_b == 0]
    lowest = min(float((origin + rotation @ p)[2]) for p in [np.zeros(3), *carried])
    top = floor_height(model) if ground is None else float(ground)
    height = max(lowest - 0.5 * ROOT_FACTOR * deepest - top, BASE_MIN_HEIGHT_M)
    length, width = BASE_SIZE_M
    base = Slab(
        np.array([origin[0] - 0.25 * length, origin[1], top + 0.5 * height]),
        0.5 * np.array([length, width, height]),
        BED_RGBA,
    )
    reach = sum(_reach(_main_points(tree, k)) for k in range(len(tree.bodies))) + GROUND_MARGIN_M
    front = 0.5 * pin_length if ground is not None else -GROUND_DEPTH_M
    soil = Slab(
        np.array([origin[0], 0.5 * (front + GROUND_DEPTH_M), top - 0.5 * GROUND_THICKNESS_M]),
        np.array([reach, 0.5 * (GROUND_DEPTH_M - front), 0.5 * GROUND_THICKNESS_M]),
        GROUND_RGBA,
        framed=False,
    )
    return base, soil


def moved_pivots(machine: Machine, designs: list[Array]) -> tuple[str, ...]:
    """Names of the model's sites and bodies at the chain pivots that differ between ``designs`` (decision values).

    A base or rocker pivot is the origin of body ``<chain>.cylinder`` / ``<chain>.rocker``; an end or
    coupler pivot is site ``<pin>.b`` of the pin closing on it (:mod:`hiab_sim.machine.dynamics.tree`).
    """
    built = [machine.with_design(d, check_bounds=False) for d in designs]  # a result's: the solver's bounds
    names = {"base": "{}.cylinder", "rocker": "{}.rocker", "end": "{}.end_pin.b", "coupler": "{}.coupler_pin.b"}
    marks = []
    for chain in machine.chains:
        for pivot in chain.pivots:
            where = [np.asarray(m.chain(chain.name).pivot(pivot.role).position, dtype=float) for m in built]
            if any(np.linalg.norm(w - where[0]) > POINT_TOLERANCE_M for w in where[1:]):
                marks.append(names[pivot.role].format(chain.name))
    return tuple(marks)

"""Dress the model's stick geoms as the machine in a rendered scene: one visual language for every video.

The simulation models draw every part as a capsule (visual only). For videos each frame's scene
is restyled (:func:`dress_scene`) from a :class:`MachineDress`, which is built from the machine's
description, never from hard-coded part names: by :func:`machine_dress` for a crane file (here)
and by :func:`hiab_sim.render.dress_machine.machine_file_dress` for a machine file. The restyling
is the same for both:

* structure (the models' ``hiab_red`` material: column, booms, links, brackets, the tool) -> box
  sections of the dress's (depth in the plane of motion, width across it) [m], in the design's
  colour of :mod:`hiab_sim.style`;
* an actuator's barrel (``cylinder`` material on its cylinder body) -> a cylinder of the dress's
  radius, dark grey; its rod (``rod`` material) -> a steel cylinder;
* every hinge and every site-based ``connect`` equality (the pins that close the loops) -> a pin
  across the plane (:data:`PIN_DIAMETER_M`), near black;
* the rigid parts the tool's link carries besides its own (the crane's end mass) -> steel blocks
  of their mass (side (m / rho_steel)^(1/3)) at their centre of mass;
* extra plates on a body (a tool's outline) and fixed world slabs (a truck bed, a machine's base,
  the ground);
* a hook under the tool point with the task's payload, while it is held, hanging under it as a
  cube of its mass (:func:`payload_box`); or, for a tool without a hook (a bucket), the payload
  sitting in the tool at its anchor point.

This module also builds the crane file's dress (:func:`machine_dress`). Sizes the data does not
give are chosen here, each with its reason next to it. Without ``hydraulic_cylinders`` the crane's
barrels and rods keep the model's capsule radii.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane

#: Square boom section of the crane file [m]: the data has no boom widths; 120 mm is the order of a
#: 3 t m crane's inner boom (a choice, drawn only: the dynamics use the data's masses and inertias).
BOOM_SECTION_M = 0.12
#: Column section [m]: a choice, wider than the booms as on loader cranes.
COLUMN_SECTION_M = 0.18
#: Barrel wall added to the bore radius [m]: a choice (a 10-12 mm wall for 19 MPa cylinders).
BARREL_WALL_M = 0.012
#: Pin diameter [m] and its length past the widest section on each side [m]: a choice.
PIN_DIAMETER_M = 0.05
PIN_OVERHANG_M = 0.02
#: Density of the end mass and payload blocks [kg/m^3]: steel.
STEEL_DENSITY = 7850.0
#: Truck bed under the column: (length, width, height) [m], a choice of a small truck's bed.
BED_SIZE_M = (2.2, 1.0, 0.16)
#: A ghost's (alpha < 1) widths across the plane and radii over the opaque design's: a choice, so that
#: where the two overlap the ghost's faces lie behind the opaque ones instead of flickering with them.
GHOST_INSET = 0.9
#: Self-lighting of the slabs: a choice, so a top face the headlight grazes does not read as a hole.
SLAB_EMISSION = 0.5
#: Plane normal of the models' world (the machine moves in MuJoCo's x-z plane): the pins' axis.
PLANE_NORMAL = np.array([0.0, 1.0, 0.0])

BARREL_RGBA = (0.22, 0.23, 0.25, 1.0)
ROD_RGBA = (0.82, 0.84, 0.86, 1.0)
PIN_RGBA = (0.08, 0.08, 0.09, 1.0)
BLOCK_RGBA = (0.36, 0.37, 0.39, 1.0)
BED_RGBA = (0.30, 0.31, 0.33, 1.0)
HOOK_RGBA = (0.95, 0.72, 0.1, 1.0)  # safety yellow
PAYLOAD_RGBA = (0.55, 0.36, 0.2, 1.0)  # crate brown: apart from the end mass's steel grey and the hook
#: Hook drawn under the tool point: its lowest point below the tool [m] (the ellipsoid's bottom), a choice.
HOOK_DROP_M = 0.27
#: Sling between the hook and the top of the payload [m]: a choice, so the two read as separate parts.
SLING_M = 0.03


@dataclass(frozen=True)
class Block:
    """A rigid body drawn as a steel block: its body in the model, centre of mass there [m], side [m]."""

    body: int
    com: Array
    side: float


@dataclass(frozen=True)
class Plate:
    """A box section drawn on a body from ``start`` to ``end`` (its frame) [m], ``depth`` x ``width`` [m]."""

    body: int
    start: Array
    end: Array
    depth: float
    width: float


@dataclass(frozen=True)
class Slab:
    """A fixed box in the world: centre and half sizes [m], colour; ``framed``: the camera keeps it in view."""

    centre: Array
    half: Array
    rgba: tuple[float, float, float, float]
    framed: bool = True


@dataclass(frozen=True)
class MachineDress:
    """What :func:`dress_scene` needs of one model: geom kinds and sizes, pins, blocks, tool, slabs.

    ``section``: a structure geom's (depth in the plane, width across it) [m]; ``radius``: a barrel's
    or rod's drawn radius [m]; ``pins``: hinge joint ids; ``pin_sites``: the first site of every
    site-based connect equality; ``hook``: a hook under the TCP, the payload hanging under it;
    otherwise the payload sits at ``payload_anchor`` (body id, point in its frame [m]) turned with
    that body. ``payload_density``: the drawn payload cube's density [kg/m^3]. ``hidden``: model
    geoms not drawn (a floor the slabs replace).
    """

    kind: dict[int, str]  # model geom id -> "structure" | "barrel" | "rod"
    section: dict[int, tuple[float, float]]
    radius: dict[int, float]
    pins: tuple[int, ...]
    pin_sites: tuple[int, ...]
    pin_length: float
    blocks: tuple[Block, ...]
    tcp_site: int
    hook: bool = True
    payload_anchor: tuple[int, Array] | None = None
    payload_density: float = STEEL_DENSITY
    plates: tuple[Plate, ...] = ()
    slabs: tuple[Slab, ...] = ()
    hidden: frozenset[int] = frozenset()


def name_of(model: mujoco.MjModel, kind: mujoco.mjtObj, index: int) -> str:
    """The name of object ``index`` of ``kind`` ("" when unnamed)."""
    return mujoco.mj_id2name(model, kind, index) or ""


def materials(model: mujoco.MjModel) -> dict[str, int]:
    """Material name -> id."""
    return {name_of(model, mujoco.mjtObj.mjOBJ_MATERIAL, m): m for m in range(model.nmat)}


def model_pins(model: mujoco.MjModel) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Hinge joint ids, and the first site of every site-based connect equality (the loops' pins)."""
    hinges = tuple(j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE)
    sites = tuple(
        int(model.eq_obj1id[e])
        for e in range(model.neq)
        if model.eq_type[e] == mujoco.mjtEq.mjEQ_CONNECT and model.eq_objtype[e] == mujoco.mjtObj.mjOBJ_SITE
    )
    return hinges, sites


def machine_dress(model: mujoco.MjModel, crane: Crane, tcp_site: str = "tcp") -> MachineDress:
    """The crane file's dress: geoms classified from the crane description (chain names, cylinder data, bodies)."""
    found = materials(model)
    cylinders = crane.hydraulic_cylinders
    chain_names = [chain.name for chain in crane.chains]
    tcp = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tcp_site)
    tool_body = int(model.site_bodyid[tcp])
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    kind: dict[int, str] = {}
    section: dict[int, tuple[float, float]] = {}
    radius: dict[int, float] = {}
    for g in range(model.ngeom):
        body = name_of(model, mujoco.mjtObj.mjOBJ_BODY, int(model.geom_bodyid[g]))
        material = int(model.geom_matid[g])
        if material < 0:
            continue
        chain = next((c for c in chain_names if body in (f"{c}_cylinder", f"{c}_rod")), "")
        data = cylinders.find(chain) if cylinders is not None and chain else None
        if material == found.get("hiab_red"):
            side = COLUMN_SECTION_M if int(model.geom_bodyid[g]) == base else BOOM_SECTION_M
            kind[g], section[g] = "structure", (side, side)
        elif material == found.get("cylinder") and not chain:  # the telescope's extension, inside its boom
            kind[g], section[g] = "structure", (0.75 * BOOM_SECTION_M, 0.75 * BOOM_SECTION_M)
        elif material == found.get("cylinder"):
            kind[g] = "barrel"
            radius[g] = 0.5 * data.bore + BARREL_WALL_M if data is not None else float(model.geom_size[g, 0])
        elif material == found.get("rod"):
            kind[g] = "rod"
            radius[g] = 0.5 * data.rod if data is not None else float(model.geom_size[g, 0])
    pins, pin_sites = model_pins(model)
    tool_link = name_of(model, mujoco.mjtObj.mjOBJ_BODY, tool_body)
    blocks = tuple(
        Block(tool_body, np.asarray(b.com, dtype=float), float((b.mass / STEEL_DENSITY) ** (1.0 / 3.0)))
        for b in crane.bodies
        if b.link == tool_link and b.name != tool_link
    )
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    bed = bed_box(model, np.asarray(data.xpos[base]))
    return MachineDress(
        kind, section, radius, pins, pin_sites, COLUMN_SECTION_M + 2.0 * PIN_OVERHANG_M, blocks, tcp,
        slabs=(Slab(*bed, BED_RGBA),),
    )  # fmt: skip


def _next(scene: mujoco.MjvScene) -> mujoco.MjvGeom | None:
    if scene.ngeom >= scene.maxgeom:
        return None
    geom = scene.geoms[scene.ngeom]
    scene.ngeom += 1
    return geom


def _add(
    scene: mujoco.MjvScene,
    kind: mujoco.mjtGeom,
    size: Sequence[float] | Array,
    pos: Array,
    mat: Array,
    rgba: Sequence[float],
) -> None:
    geom = _next(scene)
    if geom is None:
        return
    mujoco.mjv_initGeom(
        geom, kind, np.asarray(size, float), np.asarray(pos, float), np.asarray(mat, float).ravel(),
        np.asarray(rgba, np.float32),
    )  # fmt: skip
    geom.size[:] = np.asarray(size, float)  # mjv_initGeom (MuJoCo 3.17) makes a cylinder's half-length its radius
    geom.category = mujoco.mjtCatBit.mjCAT_DECOR


def section_frame(axis: Array) -> Array:
    """Rotation whose z column is ``axis`` and whose y column is the plane normal made normal to it."""
    z = np.asarray(axis, float) / max(float(np.linalg.norm(axis)), 1e-12)
    y = PLANE_NORMAL - (PLANE_NORMAL @ z) * z
    if np.linalg.norm(y) < 1e-9:  # an axis across the plane: any normal will do
        y = np.cross(z, [1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.cross(z, [0.0, 0.0, 1.0])
    y /= np.linalg.norm(y)
    return np.column_stack([np.cross(y, z), y, z])


def dress_scene(
    scene: mujoco.MjvScene,
    span: tuple[int, int],
    model: mujoco.MjModel,
    data: mujoco.MjData,
    dress: MachineDress,
    colour: Sequence[float],
    alpha: float = 1.0,
    ground: bool = True,
    payload_kg: float = 0.0,
) -> None:
    """Restyle the model's geoms of scene indices ``span`` = [start, stop) and add pins, blocks, tool, slabs.

    ``colour`` (RGB(A) in [0, 1]) paints the structure; ``alpha`` < 1 draws everything as a ghost,
    set back behind the opaque design where they overlap (:data:`GHOST_INSET`), and ``ground``
    False leaves the slabs to the opaque design. A ``payload_kg`` > 0 (the mass
    held at this frame) is drawn with the tool (:func:`payload_box`); 0 draws none.
    """
    structure = (*colour[:3], alpha)
    inset = 1.0 if alpha >= 1.0 else GHOST_INSET
    for i in range(*span):
        geom = scene.geoms[i]
        if geom.objtype != mujoco.mjtObj.mjOBJ_GEOM:
            continue
        if geom.objid in dress.hidden:
            geom.rgba[3] = 0.0
            continue
        if geom.objid not in dress.kind:
            continue
        kind = dress.kind[geom.objid]
        half = float(geom.size[2])  # a scene capsule's size is (radius, radius, half-length)
        if kind == "structure":
            depth, width = dress.section[geom.objid]
            geom.type = mujoco.mjtGeom.mjGEOM_BOX
            geom.mat[:] = section_frame(np.asarray(geom.mat).reshape(3, 3)[:, 2])
            geom.size[:] = (0.5 * depth, 0.5 * width * inset, half + 0.25 * depth)
            geom.rgba[:] = structure
        else:
            geom.type = mujoco.mjtGeom.mjGEOM_CYLINDER
            r = dress.radius[geom.objid] * inset
            geom.size[:] = (r, r, half)
            geom.rgba[:] = (*(BARREL_RGBA if kind == "barrel" else ROD_RGBA)[:3], alpha)
        geom.emission = 0.15
    _pins(scene, data, dress, alpha, inset)
    for block in dress.blocks:
        rotation = data.xmat[block.body].reshape(3, 3)
        centre = data.xpos[block.body] + rotation @ block.com
        half = 0.5 * block.side
        _add(scene, mujoco.mjtGeom.mjGEOM_BOX, (half, half, half), centre, rotation, (*BLOCK_RGBA[:3], alpha))
    for plate in dress.plates:
        start, end = plate_ends(data, plate)
        length = float(np.linalg.norm(end - start))
        size = (0.5 * plate.depth, 0.5 * plate.width * inset, 0.5 * length + 0.25 * plate.depth)
        _add(scene, mujoco.mjtGeom.mjGEOM_BOX, size, 0.5 * (start + end), section_frame(end - start), structure)
    eye = np.eye(3)
    if dress.hook:
        tool = data.site_xpos[dress.tcp_site]
        hook = (*HOOK_RGBA[:3], alpha)
        _add(scene, mujoco.mjtGeom.mjGEOM_CYLINDER, (0.012, 0.012, 0.09), tool - [0, 0, 0.09], eye, hook)
        _add(scene, mujoco.mjtGeom.mjGEOM_ELLIPSOID, (0.05, 0.02, 0.05), tool - [0, 0, 0.22], eye, hook)
    if payload_kg > 0.0:
        load_centre, load_half, rotation = payload_box(data, dress, payload_kg)
        _add(scene, mujoco.mjtGeom.mjGEOM_BOX, load_half, load_centre, rotation, (*PAYLOAD_RGBA[:3], alpha))
    if ground:
        for slab in dress.slabs:
            _add(scene, mujoco.mjtGeom.mjGEOM_BOX, slab.half, slab.centre, eye, slab.rgba)
            scene.geoms[scene.ngeom - 1].emission = SLAB_EMISSION


def _pins(scene: mujoco.MjvScene, data: mujoco.MjData, dress: MachineDress, alpha: float, inset: float) -> None:
    """A pin across the plane at every hinge anchor and every loop-closing site (``inset``: its length's share)."""
    mat = section_frame(PLANE_NORMAL)
    size = (0.5 * PIN_DIAMETER_M, 0.5 * PIN_DIAMETER_M, 0.5 * dress.pin_length * inset)
    where = [data.xanchor[j] for j in dress.pins] + [data.site_xpos[s] for s in dress.pin_sites]
    for centre in where:
        _add(scene, mujoco.mjtGeom.mjGEOM_CYLINDER, size, centre, mat, (*PIN_RGBA[:3], alpha))


def plate_ends(data: mujoco.MjData, plate: Plate) -> tuple[Array, Array]:
    """World positions [m] of a plate's two ends at the current pose."""
    rotation = data.xmat[plate.body].reshape(3, 3)
    origin = data.xpos[plate.body]
    return origin + rotation @ plate.start, origin + rotation @ plate.end


def floor_height(model: mujoco.MjModel) -> float:
    """World height of the model's floor plane [m] (0 without one)."""
    planes = np.nonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)[0]
    return float(model.geom_pos[planes[0], 2]) if len(planes) else 0.0


def bed_box(model: mujoco.MjModel, foot: Array) -> tuple[Array, Array]:
    """Centre and half sizes [m] of the truck bed: on the floor, under the column's ``foot`` [m], reaching behind it."""
    floor = floor_height(model)
    length, _width, height = BED_SIZE_M
    return np.array([foot[0] - 0.25 * length, foot[1], floor + 0.5 * height]), 0.5 * np.array(BED_SIZE_M)


def payload_box(data: mujoco.MjData, dress: MachineDress, mass: float) -> tuple[Array, Array, Array]:
    """Centre, half sizes [m] and rotation of the payload of ``mass`` [kg], drawn as a cube.

    The study gives the payload's mass only (a point mass at the TCP, :mod:`hiab_sim.study.spec.payload`);
    its drawn size is a choice: a cube of that mass at ``dress.payload_density``, side (m / rho)^(1/3)
    (150 kg of steel: 0.27 m), hanging under the hook or, without one, at the tool's anchor point
    and turned with the tool. It is drawn, not simulated: the dynamics carry the point mass.
    """
    side = float((mass / dress.payload_density) ** (1.0 / 3.0))
    half = np.full(3, 0.5 * side)
    if dress.hook or dress.payload_anchor is None:
        tool = data.site_xpos[dress.tcp_site]
        return tool - [0.0, 0.0, HOOK_DROP_M + SLING_M + 0.5 * side], half, np.eye(3)
    body, point = dress.payload_anchor
    rotation = data.xmat[body].reshape(3, 3)
    return data.xpos[body] + rotation @ point, half, rotation.copy()


_CORNERS = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1], indexing="ij")).reshape(3, 8).T


def dress_points(model: mujoco.MjModel, data: mujoco.MjData, dress: MachineDress, payload_kg: float = 0.0) -> Array:
    """World points [m] the dressing adds beyond the model's geoms (blocks, tool, payload, slabs), for framing."""
    del model  # the slabs are fixed in the world
    points = [data.site_xpos[dress.tcp_site] - [0.0, 0.0, 0.3 if dress.hook else 0.0]]
    if payload_kg > 0.0:
        centre, half, rotation = payload_box(data, dress, payload_kg)
        points.extend(centre + (_CORNERS * half) @ rotation.T)
    for block in dress.blocks:
        rotation = data.xmat[block.body].reshape(3, 3)
        centre = data.xpos[block.body] + rotation @ block.com
        points.extend(centre + (0.5 * block.side * _CORNERS) @ rotation.T)
    for plate in dress.plates:
        points.extend(plate_ends(data, plate))
    for slab in dress.slabs:
        if slab.framed:
            points.extend(slab.centre + _CORNERS * slab.half)
    return np.asarray(points, dtype=float)

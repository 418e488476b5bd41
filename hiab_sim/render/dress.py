"""Dress the model's stick geoms as the machine in a rendered scene: one visual language for every video.

The simulation model draws every part as a capsule (visual only). For videos each frame's scene
is restyled from the crane description, never from hard-coded part names:

* structure (the model's ``hiab_red`` material: column, booms, telescope carrier) -> box
  sections of :data:`BOOM_SECTION_M`, in the design's colour of :mod:`hiab_sim.style`;
* a chain's cylinder barrel (``cylinder`` material on body ``<chain>_cylinder``) -> a cylinder of
  the bore of ``hydraulic_cylinders.<chain>`` plus :data:`BARREL_WALL_M`, dark grey;
* its rod (``rod`` material on ``<chain>_rod``) -> a cylinder of the rod diameter of the data, steel;
* the telescope's extension (``cylinder`` material on the telescope rod) -> a box section
  slightly smaller than the boom it slides in;
* every hinge -> a pin across the plane (:data:`PIN_DIAMETER_M`), near black;
* the rigid bodies carried by the tool's link other than the link's own part (the end mass)
  -> steel blocks of their mass (side (m / rho_steel)^(1/3)) at their centre of mass;
* a hook under the tool point, a column foot and a truck bed standing on the model's floor;
* the task's payload, while it is held, as a steel cube of its mass (side (m / rho_steel)^(1/3))
  hanging under the hook (:func:`payload_box`).

Sizes the data does not give are chosen here, each with its reason next to it. Without
``hydraulic_cylinders`` the barrels and rods keep the model's capsule radii.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from hiab_sim.crane.description import Crane

Array = NDArray[np.float64]

#: Square boom section [m]: the data has no boom widths; 120 mm is the order of a 3 t m crane's
#: inner boom (a choice, drawn only: the dynamics use the data's masses and inertias).
BOOM_SECTION_M = 0.12
#: Column section [m]: a choice, wider than the booms as on loader cranes.
COLUMN_SECTION_M = 0.18
#: Barrel wall added to the bore radius [m]: a choice (a 10-12 mm wall for 19 MPa cylinders).
BARREL_WALL_M = 0.012
#: Pin diameter [m] and its length past the boom section on each side [m]: a choice.
PIN_DIAMETER_M = 0.05
PIN_OVERHANG_M = 0.02
#: Density of the end mass and payload blocks [kg/m^3]: steel.
STEEL_DENSITY = 7850.0
#: Truck bed under the column: (length, width, height) [m], a choice of a small truck's bed.
BED_SIZE_M = (2.2, 1.0, 0.16)

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
class MachineDress:
    """What :func:`dress_scene` needs of one model: geom kinds and radii, pins, blocks, tool site."""

    kind: dict[int, str]  # model geom id -> "structure" | "column" | "barrel" | "rod" | "extension"
    radius: dict[int, float]  # barrels and rods: drawn radius [m]
    pins: tuple[int, ...]  # hinge joint ids
    blocks: tuple[Block, ...]
    tcp_site: int
    base_body: int


def _name(model: mujoco.MjModel, kind: mujoco.mjtObj, index: int) -> str:
    return mujoco.mj_id2name(model, kind, index) or ""


def machine_dress(model: mujoco.MjModel, crane: Crane, tcp_site: str = "tcp") -> MachineDress:
    """Classify the model's geoms from the crane description (chain names, cylinder data, bodies)."""
    materials = {_name(model, mujoco.mjtObj.mjOBJ_MATERIAL, m): m for m in range(model.nmat)}
    cylinders = crane.hydraulic_cylinders
    chain_names = [chain.name for chain in crane.chains]
    tcp = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tcp_site)
    tool_body = int(model.site_bodyid[tcp])
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    kind: dict[int, str] = {}
    radius: dict[int, float] = {}
    for g in range(model.ngeom):
        body = _name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.geom_bodyid[g]))
        material = int(model.geom_matid[g])
        if material < 0:
            continue
        chain = next((c for c in chain_names if body in (f"{c}_cylinder", f"{c}_rod")), "")
        if material == materials.get("hiab_red"):
            kind[g] = "column" if int(model.geom_bodyid[g]) == base else "structure"
        elif material == materials.get("cylinder") and not chain:
            kind[g] = "extension"
        elif material == materials.get("cylinder"):
            kind[g] = "barrel"
            data = getattr(cylinders, chain, None) if cylinders is not None and chain else None
            radius[g] = 0.5 * data.bore + BARREL_WALL_M if data is not None else float(model.geom_size[g, 0])
        elif material == materials.get("rod"):
            kind[g] = "rod"
            data = getattr(cylinders, chain, None) if cylinders is not None and chain else None
            radius[g] = 0.5 * data.rod if data is not None else float(model.geom_size[g, 0])
    pins = tuple(j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE)
    tool_link = _name(model, mujoco.mjtObj.mjOBJ_BODY, tool_body)
    blocks = tuple(
        Block(tool_body, np.asarray(b.com, dtype=float), float((b.mass / STEEL_DENSITY) ** (1.0 / 3.0)))
        for b in crane.bodies
        if b.link == tool_link and b.name != tool_link
    )
    return MachineDress(kind, radius, pins, blocks, tcp, base)


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
    geom.category = mujoco.mjtCatBit.mjCAT_DECOR


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
    """Restyle the model's geoms of scene indices ``span`` = [start, stop) and add pins, blocks, hook, bed.

    ``colour`` (RGB(A) in [0, 1]) paints the structure; ``alpha`` < 1 draws everything as a ghost
    (and ``ground`` False leaves the bed to the opaque design). A ``payload_kg`` > 0 (the mass
    held at this frame) hangs under the hook (:func:`payload_box`); 0 draws none.
    """
    structure = (*colour[:3], alpha)
    for i in range(*span):
        geom = scene.geoms[i]
        if geom.objtype != mujoco.mjtObj.mjOBJ_GEOM or geom.objid not in dress.kind:
            continue
        kind = dress.kind[geom.objid]
        half = float(geom.size[2])  # a scene capsule's size is (radius, radius, half-length)
        if kind in ("structure", "column", "extension"):
            side = {"structure": BOOM_SECTION_M, "column": COLUMN_SECTION_M, "extension": 0.75 * BOOM_SECTION_M}[kind]
            geom.type = mujoco.mjtGeom.mjGEOM_BOX
            geom.size[:] = (0.5 * side, 0.5 * side, half + 0.25 * side)
            geom.rgba[:] = structure
        else:
            geom.type = mujoco.mjtGeom.mjGEOM_CYLINDER
            geom.size[:] = (dress.radius[geom.objid], dress.radius[geom.objid], half)
            geom.rgba[:] = (*(BARREL_RGBA if kind == "barrel" else ROD_RGBA)[:3], alpha)
        geom.emission = 0.15
    eye = np.eye(3)
    for j in dress.pins:
        axis = data.xaxis[j]
        mat = _frame_with_z(axis)
        length = COLUMN_SECTION_M + 2.0 * PIN_OVERHANG_M
        _add(
            scene, mujoco.mjtGeom.mjGEOM_CYLINDER, (0.5 * PIN_DIAMETER_M, 0.5 * PIN_DIAMETER_M, 0.5 * length),
            data.xanchor[j], mat, (*PIN_RGBA[:3], alpha),
        )  # fmt: skip
    for block in dress.blocks:
        rotation = data.xmat[block.body].reshape(3, 3)
        centre = data.xpos[block.body] + rotation @ block.com
        half = 0.5 * block.side
        _add(scene, mujoco.mjtGeom.mjGEOM_BOX, (half, half, half), centre, rotation, (*BLOCK_RGBA[:3], alpha))
    tool = data.site_xpos[dress.tcp_site]
    _add(scene, mujoco.mjtGeom.mjGEOM_CYLINDER, (0.012, 0.012, 0.09), tool - [0, 0, 0.09], eye, (*HOOK_RGBA[:3], alpha))
    _add(scene, mujoco.mjtGeom.mjGEOM_ELLIPSOID, (0.05, 0.02, 0.05), tool - [0, 0, 0.22], eye, (*HOOK_RGBA[:3], alpha))
    if payload_kg > 0.0:
        load_centre, load_half = payload_box(data, dress, payload_kg)
        _add(scene, mujoco.mjtGeom.mjGEOM_BOX, load_half, load_centre, eye, (*PAYLOAD_RGBA[:3], alpha))
    if ground:
        _ground(scene, model, data, dress)


def _frame_with_z(axis: Array) -> Array:
    """A rotation matrix whose z column is ``axis``."""
    z = np.asarray(axis, float) / max(float(np.linalg.norm(axis)), 1e-12)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def floor_height(model: mujoco.MjModel) -> float:
    """World height of the model's floor plane [m] (0 without one)."""
    planes = np.nonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)[0]
    return float(model.geom_pos[planes[0], 2]) if len(planes) else 0.0


def _ground(scene: mujoco.MjvScene, model: mujoco.MjModel, data: mujoco.MjData, dress: MachineDress) -> None:
    """The truck bed the column stands on, from the floor up to the column's foot."""
    centre, half = bed_box(model, data, dress)
    _add(scene, mujoco.mjtGeom.mjGEOM_BOX, half, centre, np.eye(3), BED_RGBA)


def bed_box(model: mujoco.MjModel, data: mujoco.MjData, dress: MachineDress) -> tuple[Array, Array]:
    """Centre and half sizes [m] of the truck bed: on the floor, under the column, reaching behind it."""
    floor = floor_height(model)
    foot = data.xpos[dress.base_body]
    length, _width, height = BED_SIZE_M
    return np.array([foot[0] - 0.25 * length, foot[1], floor + 0.5 * height]), 0.5 * np.array(BED_SIZE_M)


def payload_box(data: mujoco.MjData, dress: MachineDress, mass: float) -> tuple[Array, Array]:
    """Centre and half sizes [m] of the payload of ``mass`` [kg]: a steel cube hanging under the hook.

    The study gives the payload's mass only (a point mass at the TCP, :mod:`hiab_sim.study.spec.payload`);
    its drawn size is a choice: a cube of steel (:data:`STEEL_DENSITY`) of that mass, side
    (m / rho)^(1/3) (150 kg: 0.27 m). It is drawn, not simulated: the dynamics carry the point mass.
    """
    side = float((mass / STEEL_DENSITY) ** (1.0 / 3.0))
    tool = data.site_xpos[dress.tcp_site]
    return tool - [0.0, 0.0, HOOK_DROP_M + SLING_M + 0.5 * side], np.full(3, 0.5 * side)


def dress_points(model: mujoco.MjModel, data: mujoco.MjData, dress: MachineDress, payload_kg: float = 0.0) -> Array:
    """World points [m] the dressing adds beyond the model's geoms (blocks, hook, payload, bed), for camera framing."""
    points = [data.site_xpos[dress.tcp_site] - [0.0, 0.0, 0.3]]
    signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1], indexing="ij")).reshape(3, 8).T
    if payload_kg > 0.0:
        centre, half = payload_box(data, dress, payload_kg)
        points.extend(centre + signs * half)
    for block in dress.blocks:
        rotation = data.xmat[block.body].reshape(3, 3)
        centre = data.xpos[block.body] + rotation @ block.com
        points.extend(centre + (0.5 * block.side * signs) @ rotation.T)
    centre, half = bed_box(model, data, dress)
    points.extend(centre + signs * half)
    return np.asarray(points, dtype=float)

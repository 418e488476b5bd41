"""Extra scene geoms and visual settings: curves, backdrop, design colours, fast CPU visuals.

Everything here edits an :class:`mujoco.MjvScene` after ``mjv_updateScene`` (or the render
settings of a model the caller owns); nothing is added to the model itself.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import mujoco
import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.render.camera import camera_axes
from hiab_sim.style import rgba

#: Design colours (RGBA) of :mod:`hiab_sim.style`: initial blue, optimal bluish green; the reference curve grey.
INITIAL_RGBA = rgba("initial")
OPTIMAL_RGBA = rgba("optimal")
REFERENCE_RGBA = (0.35, 0.35, 0.35, 1.0)
BACKDROP_RGBA = (0.93, 0.95, 0.97, 1.0)
#: Most segments drawn per polyline (longer curves are decimated) and line width [px].
MAX_SEGMENTS = 240
LINE_WIDTH = 3.0


def design_rgba(design: str) -> tuple[float, float, float, float]:
    """A design's colour (RGBA in [0, 1]): the initial design's, and the optimal one's for any other name."""
    return INITIAL_RGBA if design == "initial" else OPTIMAL_RGBA


def _next_geom(scene: mujoco.MjvScene) -> mujoco.MjvGeom | None:
    return None if scene.ngeom >= scene.maxgeom else scene.geoms[scene.ngeom]


def add_polyline(scene: mujoco.MjvScene, points: Array, rgba: Sequence[float], width: float = LINE_WIDTH) -> None:
    """Append a polyline through ``points`` (P, 3) [m] as line geoms, decimated to MAX_SEGMENTS."""
    points = np.asarray(points, dtype=float)
    if len(points) < 2:
        return
    if len(points) > MAX_SEGMENTS + 1:
        points = points[np.linspace(0, len(points) - 1, MAX_SEGMENTS + 1).round().astype(int)]
    colour = np.asarray(rgba, dtype=np.float32)
    identity = np.eye(3).ravel()
    for start, end in itertools.pairwise(points):
        geom = _next_geom(scene)
        if geom is None:
            return
        mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_LINE, np.zeros(3), np.zeros(3), identity, colour)
        mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_LINE, width, start, end)
        geom.category = mujoco.mjtCatBit.mjCAT_DECOR
        scene.ngeom += 1


def add_ball(scene: mujoco.MjvScene, centre: Array, radius: float, rgba: Sequence[float]) -> None:
    """Append a self-lit ball of ``radius`` [m] at ``centre`` (a marker: a moved pivot)."""
    geom = _next_geom(scene)
    if geom is None:
        return
    colour = np.asarray((*rgba[:3], 1.0), dtype=np.float32)
    size = np.array([radius, radius, radius])
    mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_SPHERE, size, np.asarray(centre, float), np.eye(3).ravel(), colour)
    geom.emission = 0.6
    geom.category = mujoco.mjtCatBit.mjCAT_DECOR
    scene.ngeom += 1


def add_backdrop(scene: mujoco.MjvScene, camera: mujoco.MjvCamera, depth: float, half_size: float) -> None:
    """Append a self-lit square backdrop facing the camera, ``depth`` [m] behind its look-at point.

    Without a skybox (costly on CPU) the background would be black.
    """
    geom = _next_geom(scene)
    if geom is None:
        return
    forward, right, up = camera_axes(float(camera.azimuth), float(camera.elevation))
    centre = np.asarray(camera.lookat) + forward * depth
    rotation = np.column_stack([right, up, -forward])
    size = np.array([half_size, half_size, 0.01])
    colour = np.asarray(BACKDROP_RGBA, dtype=np.float32)
    mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_BOX, size, centre, rotation.ravel(), colour)
    geom.emission = 1.0
    geom.specular = 0.0
    geom.category = mujoco.mjtCatBit.mjCAT_DECOR
    scene.ngeom += 1


def tint_geoms(scene: mujoco.MjvScene, start: int, rgba: Sequence[float], weight: float = 0.55) -> None:
    """Blend the colour of the scene's dynamic geoms from index ``start`` on towards ``rgba``."""
    target = np.asarray(rgba, dtype=np.float32)
    for i in range(start, scene.ngeom):
        geom = scene.geoms[i]
        if geom.category == mujoco.mjtCatBit.mjCAT_DYNAMIC:
            geom.rgba[:3] = (1.0 - weight) * geom.rgba[:3] + weight * target[:3]
            geom.rgba[3] = min(float(geom.rgba[3]), float(target[3]))


def _geom_features(scene: mujoco.MjvScene, stop: int) -> tuple[NDArray[np.int_], Array]:
    """Type and (both axis ends, size) (n, 9) [m] of the scene's first ``stop`` geoms: placement and orientation."""
    types = np.array([int(scene.geoms[i].type) for i in range(stop)], dtype=int)
    features = np.empty((stop, 9))
    for i in range(stop):
        geom = scene.geoms[i]
        pos, size = np.asarray(geom.pos, dtype=float), np.asarray(geom.size, dtype=float)
        axis = np.asarray(geom.mat, dtype=float).reshape(3, 3)[:, 2] * size[2]
        features[i] = np.concatenate([pos + axis, pos - axis, size])
    return types, features


def drop_coincident(scene: mujoco.MjvScene, start: int, tolerance: float = 1e-4) -> None:
    """Remove the geoms from index ``start`` on that coincide with one before ``start`` to within ``tolerance`` [m].

    Coincide: the same type, both ends of the axis and the sizes within ``tolerance``. Overlaid
    designs share their booms (link lengths move only the cylinders): drawing the shared geoms
    twice would only blend their colours, or, a fraction of a pixel apart, make them flicker. Kept
    geoms are compacted in place.
    """
    types, features = _geom_features(scene, scene.ngeom)
    earlier_types, earlier = types[:start], features[:start]
    kept = start
    for i in range(start, scene.ngeom):
        same = earlier_types == types[i]
        if same.any() and np.min(np.max(np.abs(earlier[same] - features[i]), axis=1)) <= tolerance:
            continue
        if kept != i:
            _copy_geom(scene.geoms[kept], scene.geoms[i])
        kept += 1
    scene.ngeom = kept


_GEOM_FIELDS = ("type", "dataid", "objtype", "objid", "category", "matid", "texcoord", "segid", "transparent",
                "size", "pos", "mat", "rgba", "emission", "specular", "shininess", "reflectance", "camdist",
                "modelrbound", "castshadow", "label", "texid", "texrepeat", "texuniform")  # fmt: skip
#: The fields this MuJoCo build has (``castshadow`` is new in MuJoCo 4.0; the pinned 3.17 lacks it).
_PRESENT_FIELDS = tuple(name for name in _GEOM_FIELDS if hasattr(mujoco.MjvGeom(), name))


def _copy_geom(target: mujoco.MjvGeom, source: mujoco.MjvGeom) -> None:
    for name in _PRESENT_FIELDS:
        value = getattr(source, name)
        if isinstance(value, np.ndarray):
            getattr(target, name)[...] = value
        else:
            setattr(target, name, value)


def set_fast_visuals(scene: mujoco.MjvScene, shadows: bool = False) -> None:
    """Shadows and reflections on or off (4-8x per frame on CPU); skybox, fog and haze off."""
    for flag in (mujoco.mjtRndFlag.mjRND_SHADOW, mujoco.mjtRndFlag.mjRND_REFLECTION):
        scene.flags[flag] = shadows
    for flag in (mujoco.mjtRndFlag.mjRND_SKYBOX, mujoco.mjtRndFlag.mjRND_FOG, mujoco.mjtRndFlag.mjRND_HAZE):
        scene.flags[flag] = False


def prepare_model(model: mujoco.MjModel) -> None:
    """Render settings of a model the caller owns: no multisampling, a brighter headlight.

    Without shadows and reflections the template's lighting looks dim; multisampling costs
    CPU time per pixel.
    """
    model.vis.quality.offsamples = 0
    model.vis.headlight.ambient[:] = np.maximum(model.vis.headlight.ambient, 0.4)
    model.vis.headlight.diffuse[:] = np.maximum(model.vis.headlight.diffuse, 0.5)

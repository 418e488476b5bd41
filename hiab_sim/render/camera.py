"""A free camera that frames a whole motion: MuJoCo's world is z up, the crane moves in x-z."""

from __future__ import annotations

import mujoco
import numpy as np

from hiab_sim.arrays import Array

#: Camera direction [deg]: looking along +y onto the x-z plane of motion, slightly from above.
AZIMUTH = 90.0
ELEVATION = -12.0


def camera_axes(azimuth: float, elevation: float) -> tuple[Array, Array, Array]:
    """Unit (forward, right, up) vectors of a MuJoCo free camera at (azimuth, elevation) [deg]."""
    az, el = np.radians(azimuth), np.radians(elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


def geom_corners(model: mujoco.MjModel, data: mujoco.MjData) -> Array:
    """World corners (8 n, 3) of the bounding boxes of the visible geoms at the current pose [m].

    Planes (infinite) are skipped, so a floor does not blow up the framing.
    """
    keep = (model.geom_type != mujoco.mjtGeom.mjGEOM_PLANE) & (model.geom_rgba[:, 3] > 0)
    aabb = model.geom_aabb[keep]  # (n, 6): centre and half sizes in the geom frame
    signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1], indexing="ij")).reshape(3, 8).T
    local = aabb[:, None, :3] + signs[None] * aabb[:, None, 3:]
    rotation = data.geom_xmat[keep].reshape(-1, 3, 3)
    world = data.geom_xpos[keep][:, None, :] + np.einsum("gij,gkj->gki", rotation, local)
    return world.reshape(-1, 3)


def fit_camera(
    points: Array,
    aspect: float,
    fovy: float,
    azimuth: float = AZIMUTH,
    elevation: float = ELEVATION,
    margin: float = 1.08,
) -> mujoco.MjvCamera:
    """A free camera at (azimuth, elevation) [deg] whose view holds all ``points`` (P, 3) [m].

    ``aspect`` is the viewport's width / height and ``fovy`` MuJoCo's vertical field of view
    [deg]. A point at offset (x, y, z) from the look-at point along (right, up, forward) is in
    view at distance D when |x| <= (D + z) tan(fovx / 2) and |y| <= (D + z) tan(fovy / 2); D is
    the smallest such distance times ``margin``, and the look-at point centres the projection.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    forward, right, up = camera_axes(azimuth, elevation)
    tan_y = np.tan(np.radians(fovy) / 2.0)
    tan_x = tan_y * aspect
    lookat = 0.5 * (points.min(axis=0) + points.max(axis=0))
    for _ in range(2):
        v = points - lookat
        x, y = v @ right, v @ up
        lookat = lookat + right * 0.5 * (x.min() + x.max()) + up * 0.5 * (y.min() + y.max())
    v = points - lookat
    x, y, z = v @ right, v @ up, v @ forward
    distance = float(np.max(np.maximum(np.abs(x) / tan_x, np.abs(y) / tan_y) - z)) * margin
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = lookat
    camera.distance = max(distance, 1e-3)
    camera.azimuth = azimuth
    camera.elevation = elevation
    return camera


def fixed_pose(camera: mujoco.MjvCamera) -> tuple[Array, Array]:
    """Position [m] and ``xyaxes`` (right, up) of a fixed MJCF camera that sees what ``camera`` sees."""
    forward, right, up = camera_axes(float(camera.azimuth), float(camera.elevation))
    position = np.asarray(camera.lookat, dtype=float) - forward * float(camera.distance)
    return position, np.concatenate([right, up])


#: The exported model's cameras: name -> (azimuth, elevation) [deg] (side view, three-quarter view).
MODEL_CAMERAS = {"side": (90.0, -12.0), "perspective": (135.0, -22.0)}


def framed_cameras(points: Array, aspect: float, fovy: float) -> dict[str, tuple[Array, Array]]:
    """Fixed poses of :data:`MODEL_CAMERAS` that each hold every point of ``points`` (P, 3) [m] in view."""
    return {
        name: fixed_pose(fit_camera(points, aspect, fovy, azimuth, elevation, margin=1.1))
        for name, (azimuth, elevation) in MODEL_CAMERAS.items()
    }

"""Screw-theory algebra on 6D spatial vectors, vectorised over time samples, numpy only.

Notation of Lynch & Park, *Modern Robotics* (2017), ch. 3 and 8, which the seed paper adopts
("screw theory notation", after eq. DDthetas) and Petrovic & Mattila (2022) use:

- a twist ``V = (omega, v)`` in a frame {i}: angular velocity [rad/s] and the linear velocity
  [m/s] of the point at {i}'s origin, both in {i}'s axes; a spatial acceleration ``dV`` is its
  time derivative in {i}'s axes [rad/s^2, m/s^2];
- a wrench ``F = (m, f)``: moment about {i}'s origin [N m] and force [N], in {i}'s axes, so that
  ``F . V`` is a power [W];
- a pose ``T = (R, p)`` of a child frame in its parent: rotation and origin position [m].

Arrays carry the samples in their leading axes: twists and wrenches are (..., 6), rotations
(..., 3, 3), positions (..., 3). Functions apply adjoints to vectors directly instead of
forming 6x6 matrices, which keeps the per-sample cost low.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array


def skew(v: ArrayLike) -> Array:
    """The 3x3 skew-symmetric matrix [v] with [v] w = v x w, (..., 3) -> (..., 3, 3)."""
    v = np.asarray(v, dtype=float)
    out = np.zeros((*v.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def rotate(R: Array, v: Array) -> Array:
    """R v for stacks of rotations (..., 3, 3) and vectors (..., 3)."""
    return np.einsum("...ij,...j->...i", R, v)


def rotate_back(R: Array, v: Array) -> Array:
    """R^T v for stacks of rotations (..., 3, 3) and vectors (..., 3)."""
    return np.einsum("...ji,...j->...i", R, v)


def spatial_inertia(mass: float, com: ArrayLike, inertia_com: ArrayLike) -> Array:
    """6x6 spatial inertia G of a rigid body about a frame's origin (Lynch & Park eq. 8.32).

    With the centre of mass ``c`` [m] and the inertia about it ``I_c`` [kg m^2], both in the
    frame's axes, ``G = [[I_c - m [c]^2, m [c]], [m [c]^T, m 1]]`` in (omega, v) ordering, so that
    the kinetic energy is ``V^T G V / 2`` [J] and the momentum ``G V`` is (angular about the
    origin, linear).
    """
    c = skew(np.asarray(com, dtype=float))
    out = np.zeros((6, 6))
    out[:3, :3] = np.asarray(inertia_com, dtype=float) - mass * c @ c
    out[:3, 3:] = mass * c
    out[3:, :3] = mass * c.T
    out[3:, 3:] = mass * np.eye(3)
    return out


def twist_to_child(R: Array, p: Array, V: Array) -> Array:
    """Ad_{T^-1} V: a twist given in a parent frame, expressed in the child {T = (R, p)} [eq. 3.83].

    omega' = R^T omega, v' = R^T (v + omega x p).
    """
    w, v = V[..., :3], V[..., 3:]
    return np.concatenate([rotate_back(R, w), rotate_back(R, v + np.cross(w, p))], axis=-1)


def wrench_to_parent(R: Array, p: Array, F: Array) -> Array:
    """Ad_{T^-1}^T F: a wrench given in the child {T = (R, p)}, expressed in the parent (eq. 3.98).

    f' = R f, m' = R m + p x f'.
    """
    f = rotate(R, F[..., 3:])
    return np.concatenate([rotate(R, F[..., :3]) + np.cross(p, f), f], axis=-1)


def ad(V: Array, W: Array) -> Array:
    """Lie bracket ad_V W = [V, W] of two twists (Lynch & Park eq. 8.38).

    ad_V W = (omega x omega_W, v x omega_W + omega x v_W).
    """
    w, v = V[..., :3], V[..., 3:]
    return np.concatenate([np.cross(w, W[..., :3]), np.cross(v, W[..., :3]) + np.cross(w, W[..., 3:])], axis=-1)


def ad_transpose(V: Array, F: Array) -> Array:
    """ad_V^T F for a twist V and a wrench F (Lynch & Park eq. 8.42).

    ad_V^T F = (-omega x m - v x f, -omega x f) = -(omega x m + v x f, omega x f).
    """
    w, v = V[..., :3], V[..., 3:]
    m, f = F[..., :3], F[..., 3:]
    return -np.concatenate([np.cross(w, m) + np.cross(v, f), np.cross(w, f)], axis=-1)


def newton_euler_wrench(G: Array, V: Array, dV: Array) -> Array:
    """Body-frame Newton-Euler wrench F = G dV - ad_V^T (G V) [N m, N] (Lynch & Park eq. 8.41).

    The wrench that the rest of the world must apply to a body with spatial inertia ``G``
    (6x6, constant in the body frame), twist ``V`` and spatial acceleration ``dV``.
    """
    GV = V @ G.T
    return dV @ G.T - ad_transpose(V, GV)

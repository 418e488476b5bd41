"""Forward kinematics of the crane's links in the source world frame {W} (y up), numpy only.

Given samples of the independent joints (theta1, theta2, xt2) and a link-length set, returns the
pose of every link frame (see :mod:`hiab_sim.crane.description`) and of the TCP {D22}, vectorised over
samples. The closed chains are solved with the trigonometry of :mod:`hiab_sim.crane.mechanism`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ClosedChain, Crane, LinkLengths, Pose
from hiab_sim.crane.names import BASE, TELESCOPE, TELESCOPE_CYLINDER, TELESCOPE_ROD, boom_link, cylinder_link, rod_link
from hiab_sim.machine.kinematics.forward import rotation_z  # the one rotation about z, shared with the generic model


@dataclass(frozen=True)
class Frames:
    """World poses of link frames: ``rotation[name]`` (T, 3, 3) and ``position[name]`` (T, 3) [m]."""

    rotation: dict[str, Array]
    position: dict[str, Array]
    stroke: dict[str, Array]  # actuator strokes x of "lift", "tilt" [m] and "telescope" (xt2)

    def point(self, link: str, local: ArrayLike) -> Array:
        """World position (T, 3) of a point given in a link frame [m]."""
        return self.position[link] + self.rotation[link] @ np.asarray(local, dtype=float)


def _compose(frames: Frames, parent: str, child: str, rotation: Array, position: Array) -> None:
    """Add child = parent * (position, rotation), both given in the parent frame."""
    frames.rotation[child] = frames.rotation[parent] @ rotation
    frames.position[child] = frames.position[parent] + np.einsum("...ij,...j->...i", frames.rotation[parent], position)


def _add_chain(frames: Frames, chain: ClosedChain, lengths: LinkLengths, theta: Array) -> None:
    xi = getattr(lengths, chain.name)
    n = theta.shape
    x = mechanism.joint_to_stroke(chain, xi, theta)
    _, q1, _ = mechanism.triangle_angles(x, xi.L, chain.L1, xi.x0)
    frames.stroke[chain.name] = x
    hinge = np.broadcast_to(chain.boom_hinge, (*n, 3))
    pivot = np.broadcast_to(chain.base_pivot(xi), (*n, 3))
    _compose(
        frames,
        chain.parent,
        boom_link(chain.name),
        rotation_z(chain.base_axis_angle + theta - chain.joint_offset),
        hinge,
    )
    _compose(frames, chain.parent, cylinder_link(chain.name), rotation_z(chain.base_axis_angle + q1), pivot)
    rod_offset = np.zeros((*n, 3))
    rod_offset[..., 0] = xi.Lc0 + x
    _compose(
        frames,
        cylinder_link(chain.name),
        rod_link(chain.name),
        np.broadcast_to(np.eye(3), (*n, 3, 3)),
        rod_offset,
    )


def forward_kinematics(
    crane: Crane, lengths: LinkLengths, theta1: ArrayLike, theta2: ArrayLike, xt2: ArrayLike
) -> Frames:
    """World poses of every link and the TCP for joint samples (any common shape)."""
    theta1, theta2, xt2 = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (theta1, theta2, xt2)))
    n = theta1.shape
    frames = Frames(
        rotation={BASE: np.broadcast_to(np.eye(3), (*n, 3, 3))},
        position={BASE: np.zeros((*n, 3))},
        stroke={TELESCOPE: xt2},
    )
    _add_chain(frames, crane.lift, lengths, theta1)
    _add_chain(frames, crane.tilt, lengths, theta2)
    tele = crane.telescope
    cyl = tele.cylinder_frame
    _compose(
        frames,
        tele.parent,
        TELESCOPE_CYLINDER,
        np.broadcast_to(np.asarray(cyl.rotation), (*n, 3, 3)),
        np.broadcast_to(np.asarray(cyl.position), (*n, 3)),
    )
    slide = np.zeros((*n, 3))
    slide[..., 0] = tele.rod_offset + xt2
    _compose(frames, TELESCOPE_CYLINDER, TELESCOPE_ROD, np.broadcast_to(np.eye(3), (*n, 3, 3)), slide)
    _attach(frames, TELESCOPE_ROD, "tcp", crane.tcp_in_telescope_rod, n)
    return frames


def _attach(frames: Frames, parent: str, child: str, pose: Pose, n: tuple[int, ...]) -> None:
    _compose(
        frames,
        parent,
        child,
        np.broadcast_to(np.asarray(pose.rotation), (*n, 3, 3)),
        np.broadcast_to(np.asarray(pose.position), (*n, 3)),
    )


def tcp_position(crane: Crane, theta1: ArrayLike, theta2: ArrayLike, xt2: ArrayLike) -> Array:
    """TCP position in {W}, (..., 3) [m]. Independent of the link lengths (the hinges are fixed)."""
    return forward_kinematics(crane, crane.default_lengths, theta1, theta2, xt2).position["tcp"]

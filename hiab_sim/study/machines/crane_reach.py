"""The crane's closed-form planar inverse kinematics: which TCP points it reaches within its joint ranges.

With the telescope xt2 prescribed, the TCP of :class:`~hiab_sim.study.motion.trajectory.TcpKinematics`,

    p = H1 + e^{i phi1} (H2 + e^{i phi2} Q),    Q = A + xt2 U,    phi_j = theta_j + offset_j,

is a two-link planar arm with link vectors H2 (lift boom) and Q (tilt boom with the telescope).
With d = p - H1 the law of cosines gives

    cos(phi2 + beta) = (|d|^2 - |H2|^2 - |Q|^2) / (2 |H2| |Q|),    beta = arg Q - arg H2,

so phi2 = +-acos(.) - beta (two elbow branches) and phi1 = arg d - arg(H2 + e^{i phi2} Q). A
point is reachable when |cos| <= 1 and one branch has theta1, theta2 within the crane's joint
ranges (``ClosedChain.joint_range``) and xt2 within the telescope's. This is independent of the
Newton iteration of :func:`hiab_sim.study.motion.trajectory.inverse_kinematics`, vectorised over
points, and used to check every point of a task's reference before any optimisation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane
from hiab_sim.study.motion.trajectory import TcpKinematics

#: What each :attr:`PlanarIk.status` code means, for error messages.
REASONS = (
    "reachable",
    "is out of the crane's reach at this telescope extension",
    "needs theta1 outside the lift joint range",
    "needs theta2 outside the tilt joint range",
    "needs xt2 outside the telescope range",
)


@dataclass(frozen=True)
class PlanarIk:
    """Closed-form IK of K points: ``joints`` (K, 3) = (theta1, theta2, xt2) of the branch in range.

    ``status`` (K,) says per point: 0 reachable within the joint ranges; 1 out of the arm's
    reach (|cos| > 1); 2 theta1 and 3 theta2 out of range on the better branch; 4 xt2 out of
    the telescope's range. Where status != 0, ``joints`` holds the closest branch (or NaN).
    """

    joints: Array
    status: Array


def _wrap(theta: Array, centre: float) -> Array:
    """Angles ``theta`` shifted by a multiple of 2 pi to lie within pi of ``centre``."""
    return centre + np.mod(theta - centre + np.pi, 2.0 * np.pi) - np.pi


def planar_ik(kin: TcpKinematics, crane: Crane, xy: ArrayLike, xt2: ArrayLike) -> PlanarIk:
    """Joints (theta1, theta2, xt2) that put the TCP at ``xy`` (K, 2) [m] with telescope ``xt2`` (K,) [m]."""
    p = np.atleast_2d(np.asarray(xy, dtype=float))
    xt = np.broadcast_to(np.asarray(xt2, dtype=float), (len(p),)).astype(float)
    d = p[:, 0] + 1j * p[:, 1] - kin.H1
    Q = kin.A + xt * kin.U
    h2, q = abs(kin.H2), np.abs(Q)
    cosine = (np.abs(d) ** 2 - h2**2 - q**2) / (2.0 * h2 * q)
    status = np.where(np.abs(cosine) <= 1.0, 0, 1)
    beta = np.angle(Q) - np.angle(kin.H2)
    ranges = [chain.joint_range for chain in crane.chains]
    centres = [0.5 * (lo + hi) for lo, hi in ranges]
    best = np.full((len(p), 2), np.nan)
    best_excess = np.full(len(p), np.inf)
    best_status = np.full(len(p), 2)
    acos = np.arccos(np.clip(cosine, -1.0, 1.0))
    for sign in (1.0, -1.0):
        phi2 = sign * acos - beta
        phi1 = np.angle(d) - np.angle(kin.H2 + np.exp(1j * phi2) * Q)
        theta1 = _wrap(phi1 - kin.offsets[0], centres[0])
        theta2 = _wrap(phi2 - kin.offsets[1], centres[1])
        excess1 = np.maximum(ranges[0][0] - theta1, theta1 - ranges[0][1]).clip(min=0.0)
        excess2 = np.maximum(ranges[1][0] - theta2, theta2 - ranges[1][1]).clip(min=0.0)
        excess = excess1 + excess2
        better = excess < best_excess
        best[better] = np.column_stack([theta1, theta2])[better]
        best_excess = np.where(better, excess, best_excess)
        best_status = np.where(better, np.where(excess1 > 0.0, 2, np.where(excess2 > 0.0, 3, 0)), best_status)
    status = np.where(status == 0, best_status, status)
    low, high = crane.telescope.joint_range
    status = np.where((status == 0) & ((xt < low) | (xt > high)), 4, status)
    return PlanarIk(joints=np.column_stack([best, xt]), status=status)

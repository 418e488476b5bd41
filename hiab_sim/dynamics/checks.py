"""Input checks shared by both inverse-dynamics paths (one place for each rule).

- Joint samples: theta1 and theta2 inside their chain's usable stroke
  (:func:`hiab_sim.crane.mechanism.check_joint_samples`, const_j, const_k), xt2 inside the
  telescope's ``joint_range`` [m]; fields ``theta1``, ``theta2``, ``xt2``.
- TCP force: shape (3,) or (T, 3), finite [N]; field ``tcp_force``.

Link lengths are checked where a model is built for them (:func:`hiab_sim.crane.mechanism.check_lengths`
via :func:`hiab_sim.model.mjcf.build_spec` or :func:`hiab_sim.dynamics.analytic_planar.planar_model`),
once per link-length set.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane import mechanism
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.names import JOINT_NAMES
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import InvalidInputError


def check_joints(crane: Crane, lengths: LinkLengths, joints: JointSamples) -> None:
    """Raise :class:`InvalidInputError` naming the joint if a position sample is out of range.

    theta1, theta2: :func:`hiab_sim.crane.mechanism.check_joint_samples` [rad]; xt2: the
    telescope's ``joint_range`` [m]. (Finiteness is checked when :class:`JointSamples` is built; the
    samples hold any number of joints, the crane's paths take its three.)
    """
    if joints.position.shape[1] != len(JOINT_NAMES):
        raise InvalidInputError(
            "joints.position", f"shape {joints.position.shape}", f"must have shape (T, {len(JOINT_NAMES)})"
        )
    for column, chain in enumerate(crane.chains):
        mechanism.check_joint_samples(
            chain, getattr(lengths, chain.name), joints.position[:, column], field=JOINT_NAMES[column]
        )
    low, high = crane.telescope.joint_range
    xt2 = joints.position[:, 2]
    outside = (xt2 < low) | (xt2 > high)
    if np.any(outside):
        raise InvalidInputError(
            JOINT_NAMES[2], float(xt2[np.argmax(outside)]), f"must lie in [{low:.6g}, {high:.6g}]", "m"
        )


def tcp_force_samples(tcp_force: ArrayLike | None, n: int) -> Array | None:
    """The TCP force broadcast to (n, 3) [N], or None when there is none.

    Raises:
        InvalidInputError: shape neither (3,) nor (n, 3), or not finite (field ``tcp_force``).

    """
    if tcp_force is None:
        return None
    force = np.asarray(tcp_force, dtype=float)
    if force.shape not in ((3,), (n, 3)):
        raise InvalidInputError("tcp_force", f"shape {force.shape}", f"must have shape (3,) or ({n}, 3)", "N")
    if not np.all(np.isfinite(force)):
        raise InvalidInputError("tcp_force", "NaN or inf", "must be finite", "N")
    return np.broadcast_to(force, (n, 3)).astype(float)

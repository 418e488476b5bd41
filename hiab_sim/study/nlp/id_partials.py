"""Partials of the inverse dynamics [f_x, v_x, a_x] = ID(theta, dtheta, ddtheta, robot(Xi)) by central differences.

Outputs Y per sample are ordered (every actuator's force f_x, then every velocity v_x, then every
acceleration a_x, in the machine's actuator order); inputs (q, dq, ddq) of the machine's joints in
its joint order, and Xi = (lift L, Lc0, Lc, tilt L, Lc0, Lc) [m] on a crane file. Steps are relative:
h = fd_step * max(1, |value|).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.dynamics.interface import InverseDynamics, make_inverse_dynamics
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples


def _outputs(act: ActuatorSamples) -> Array:
    return np.concatenate([act.force, act.velocity, act.acceleration], axis=1)


def id_joint_partials(
    model: InverseDynamics, joints: JointSamples, fd_step: float, tcp_force: ArrayLike | None
) -> Array:
    """dY/dq per sample by central differences, (K, 3 m outputs, 3 n inputs) for n joints and m actuators.

    The inputs are (q, dq, ddq) of the n joints (9 on the crane). All K samples and all 3 n
    perturbations go into one ID call of 6 n K samples: samples are independent, so perturbing
    them together is exact bookkeeping, not an approximation.
    """
    K, n = joints.position.shape
    base = np.concatenate([joints.position, joints.velocity, joints.acceleration], axis=1)  # (K, 3n)
    h = fd_step * np.maximum(1.0, np.abs(base))  # (K, 3n)
    batch = np.repeat(base[None], 6 * n, axis=0)  # (6n, K, 3n)
    for j in range(3 * n):
        batch[2 * j, :, j] += h[:, j]
        batch[2 * j + 1, :, j] -= h[:, j]
    flat = batch.reshape(6 * n * K, 3 * n)
    # a constant force (3,) serves every sample; a force per sample (K, 3) is repeated for each perturbation
    stacked = tcp_force
    if tcp_force is not None and np.ndim(tcp_force) == 2:
        stacked = np.tile(np.asarray(tcp_force, dtype=float), (6 * n, 1))
    samples = JointSamples(flat[:, :n], flat[:, n : 2 * n], flat[:, 2 * n :])
    out = _outputs(model(samples, tcp_force=stacked))
    out = out.reshape(6 * n, K, out.shape[1])
    d = (out[0::2] - out[1::2]) / (2.0 * h.T[:, :, None])  # (3n inputs, K, 3m outputs)
    return np.transpose(d, (1, 2, 0))


def id_length_partials(
    crane: Crane, lengths: LinkLengths, joints: JointSamples, path: str, fd_step: float, tcp_force: ArrayLike | None
) -> Array:
    """dY/dXi per sample by central differences, (K, 9, 6) [per m].

    On the analytic path the 12 perturbed designs go through one stacked ID call
    (:func:`~hiab_sim.dynamics.analytic_batch.batched_inverse_dynamics`); on ``mujoco`` one model is
    built per perturbed Xi.
    """
    xi = lengths.as_array()
    if path == "analytic":
        return _batched_length_partials(crane, xi, joints, fd_step, tcp_force)
    out = np.zeros((len(joints), 9, 6))
    for i in range(6):
        h = fd_step * max(1.0, abs(xi[i]))
        values = []
        for sign in (1.0, -1.0):
            x = xi.copy()
            x[i] += sign * h
            model = make_inverse_dynamics(crane, LinkLengths.from_array(x), path)
            values.append(_outputs(model(joints, tcp_force=tcp_force)))
        out[:, :, i] = (values[0] - values[1]) / (2.0 * h)
    return out


def _batched_length_partials(
    crane: Crane, xi: Array, joints: JointSamples, fd_step: float, tcp_force: ArrayLike | None
) -> Array:
    """:func:`id_length_partials` on the analytic path: designs xi +- h e_i stacked into one ID call."""
    h = fd_step * np.maximum(1.0, np.abs(xi))  # (6,)
    designs = np.repeat(xi[None], 12, axis=0)
    designs[0::2] += np.diag(h)
    designs[1::2] -= np.diag(h)
    force, velocity, acceleration, _ = batched_inverse_dynamics(
        crane, designs, joints.position, joints.velocity, joints.acceleration, tcp_force
    )
    y = np.concatenate([force, velocity, acceleration], axis=2)  # (12, K, 9)
    d = (y[0::2] - y[1::2]) / (2.0 * h[:, None, None])  # (6 lengths, K, 9 outputs)
    return np.transpose(d, (1, 2, 0))

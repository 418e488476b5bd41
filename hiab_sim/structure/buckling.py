"""Buckling of each EMLA's screw under its push force: Euler with end fixity, Johnson at low slenderness.

The screw is a solid round column of its thread root diameter d_r (section A = pi d_r^2 / 4,
I = pi d_r^4 / 64, radius of gyration r = d_r / 4) and length l, the actuator's column length
along the motion (:func:`hiab_sim.structure.actuators.column_length`). With the catalogues'
mounting factor N (THK General Catalog, Ball Screw, Permissible Axial Load, eq. (5): eta1 = 1
pinned-pinned, 2 fixed-supported, 4 fixed-fixed, 0.25 fixed-free), the effective length is
l_e = l / sqrt(N) and the slenderness lambda = l_e / r. The critical load is

    Euler     P_cr = pi^2 E I / l_e^2 = pi^2 E A / lambda^2,            lambda >= lambda_c,
    Johnson   P_cr = A sigma_y (1 - sigma_y lambda^2 / (4 pi^2 E)),      lambda <  lambda_c,

with lambda_c = pi sqrt(2 E / sigma_y), where both give A sigma_y / 2 with the same slope
(Shigley's Mechanical Engineering Design, columns of intermediate length). The push force f
(f > 0 compresses the actuator, :mod:`hiab_sim.dynamics.samples`) must stay below P_cr / n
with the safety factor n (default 2: the 0.5 THK and NSK multiply their buckling load by).

The row of one actuator at one sample is the utilisation u = n f / P_cr (<= 1 holds), written
for the NLP as 1 - u >= 0; its partials are exact:

    du = n (df P_cr - f dP_cr) / P_cr^2,   dP_cr = (dP_cr/dl) (dl/dtheta dtheta + dl/dXi dXi),
    dP_cr/dl = -2 P_cr / l (Euler),  -A sigma_y^2 lambda^2 / (2 pi^2 E l) (Johnson).

Everything is numpy over samples (any leading shape).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_range
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.emla.config import EmlaParams, EmlaSet, ScrewColumn
from hiab_sim.structure.actuators import Actuator, actuators, column_length, n_xi

#: Default safety factor on the buckling load [-]: THK (eq. (5)) and NSK multiply P_cr by 0.5.
DEFAULT_SAFETY_FACTOR = 2.0


def transition_slenderness(screw: ScrewColumn) -> float:
    """lambda_c = pi sqrt(2 E / sigma_y) [-]: Euler above, Johnson below."""
    return math.pi * math.sqrt(2.0 * screw.elastic_modulus / screw.yield_strength)


def critical_load(screw: ScrewColumn, length: ArrayLike) -> tuple[Array, Array]:
    """Critical load P_cr [N] of the screw as a column of ``length`` [m], and dP_cr/dlength [N/m]."""
    size = np.asarray(length, dtype=float)
    d, E, sy = screw.root_diameter, screw.elastic_modulus, screw.yield_strength
    area = math.pi * d**2 / 4.0
    radius = d / 4.0
    slender = size / (math.sqrt(screw.end_fixity_factor) * radius)
    euler = math.pi**2 * E * area / np.maximum(slender, 1e-300) ** 2
    johnson = area * sy * (1.0 - sy * slender**2 / (4.0 * math.pi**2 * E))
    is_euler = slender >= transition_slenderness(screw)
    load = np.where(is_euler, euler, johnson)
    slope = np.where(
        is_euler,
        -2.0 * euler / np.maximum(size, 1e-300),
        -area * sy**2 * slender / (2.0 * math.pi**2 * E * np.maximum(size, 1e-300)) * slender,
    )
    return load, slope


@dataclass(frozen=True)
class BucklingSamples:
    """Per actuator with screw data: column length, critical load and utilisation along the motion.

    ``names`` (n,); ``length`` [m], ``critical_load`` [N], ``force`` [N] (> 0 pushes) and
    ``utilisation`` u = n f / P_cr [-] (feasible where <= 1), each (T, n).
    """

    names: tuple[str, ...]
    safety_factor: float
    length: Array
    critical_load: Array
    force: Array
    utilisation: Array

    @property
    def margin(self) -> Array:
        """1 - u per sample and actuator [-] (the NLP's row, >= 0 holds)."""
        return 1.0 - self.utilisation

    def worst(self) -> dict[str, float]:
        """Largest utilisation over the samples per actuator [-]."""
        return {name: float(np.max(self.utilisation[:, k])) for k, name in enumerate(self.names)}

    def reserve(self) -> dict[str, float]:
        """Smallest P_cr / (n f) over the pushing samples per actuator [-] (inf if it never pushes)."""
        out = {}
        for k, name in enumerate(self.names):
            u = np.max(self.utilisation[:, k])
            out[name] = float(1.0 / u) if u > 0.0 else math.inf
        return out


def buckled_actuators(crane: Crane, emlas: EmlaSet) -> tuple[tuple[Actuator, EmlaParams], ...]:
    """The actuators whose EMLA data have a ``screw`` section, with their parameters."""
    by_name = {params.name: params for params in emlas}
    return tuple((a, by_name[a.name]) for a in actuators(crane) if by_name[a.name].screw is not None)


def check_safety_factor(value: float) -> None:
    """Raise :class:`hiab_sim.errors.InvalidInputError` unless 1 <= value <= 10."""
    check_range("buckling_safety_factor", value, 1.0, 10.0)


def buckling_samples(
    crane: Crane,
    emlas: EmlaSet,
    lengths: LinkLengths,
    position: ArrayLike,
    force: ArrayLike,
    safety_factor: float = DEFAULT_SAFETY_FACTOR,
) -> BucklingSamples:
    """Buckling utilisation of every actuator with screw data at joint samples (T, 3) and forces (T, 3) [N]."""
    check_safety_factor(safety_factor)
    f = np.asarray(force, dtype=float)
    names, cols, loads, pushes = [], [], [], []
    for actuator, params in buckled_actuators(crane, emlas):
        screw = params.screw
        assert screw is not None
        s, _, _ = column_length(crane, lengths, actuator, position, screw.retracted_length)
        load, _ = critical_load(screw, s)
        names.append(actuator.name)
        cols.append(s)
        loads.append(load)
        pushes.append(f[:, actuator.column])
    length, load, push = (np.stack(v, axis=1) if v else np.zeros((f.shape[0], 0)) for v in (cols, loads, pushes))
    return BucklingSamples(tuple(names), safety_factor, length, load, push, safety_factor * push / load)


def utilisation_partials(
    crane: Crane,
    emlas: EmlaSet,
    lengths: LinkLengths,
    position: ArrayLike,
    force: ArrayLike,
    dforce_dq: ArrayLike,
    dforce_dxi: ArrayLike,
    safety_factor: float = DEFAULT_SAFETY_FACTOR,
) -> tuple[Array, Array]:
    """Exact partials of the utilisation u = n f / P_cr, (T, n, n_q) w.r.t. each sample's q and (T, n, n_xi).

    Args:
        crane: The crane.
        emlas: The EMLA set (actuators with a ``screw`` section give rows).
        lengths: Link lengths Xi [m].
        position: Joint samples (T, n_joints).
        force: Actuator forces (T, n_actuators) [N].
        dforce_dq: d f / d q of each sample's own inputs q (T, n_actuators, n_q) (n_q may include
            rates and accelerations after the positions, as the NLP's q9 does) [N per unit].
        dforce_dxi: d f / d Xi (T, n_actuators, n_xi) [N/m].
        safety_factor: n [-].

    """
    check_safety_factor(safety_factor)
    f = np.asarray(force, dtype=float)
    df_dq = np.asarray(dforce_dq, dtype=float)
    df_dxi = np.asarray(dforce_dxi, dtype=float)
    rows = buckled_actuators(crane, emlas)
    T, nq = f.shape[0], df_dq.shape[2]
    out_q = np.zeros((T, len(rows), nq))
    out_xi = np.zeros((T, len(rows), n_xi(crane)))
    for r, (actuator, params) in enumerate(rows):
        screw = params.screw
        assert screw is not None
        k = actuator.column
        s, ds_dq, ds_dxi = column_length(crane, lengths, actuator, position, screw.retracted_length)
        load, slope = critical_load(screw, s)
        fk = f[:, k]
        factor = safety_factor / load
        dP_dq = np.zeros((T, nq))
        dP_dq[:, k] = slope * ds_dq
        out_q[:, r] = factor[:, None] * (df_dq[:, k] - (fk / load)[:, None] * dP_dq)
        out_xi[:, r] = factor[:, None] * (df_dxi[:, k] - (fk / load)[:, None] * (slope[:, None] * ds_dxi))
    return out_q, out_xi

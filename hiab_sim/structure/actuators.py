"""Which chain each actuator drives, and its column length along the motion with exact partials.

The crane description orders its actuators as :data:`hiab_sim.crane.names.ACTUATOR_NAMES`: first
one per closed chain (``crane.chains``, in that order, each named after its chain), then the
direct actuator that is itself the prismatic joint. Joint samples carry the joint each actuator
drives in the same column, and Xi = (xi of chain 0, xi of chain 1, ...), xi = (L, Lc0, Lc).

Column length ("pin to pin"). A chain's actuator spans its triangle's side between the cylinder
base pivot {Bc} and the rod-end pivot {Tc} (seed eq. qus_a):

    s = sqrt(L^2 + L1^2 - 2 L L1 cos q) = x + x0,    q = psi - theta,

so s depends on theta and on L only: ds/dtheta = -L L1 sin q / s and ds/dL = (L - L1 cos q) / s
(:func:`hiab_sim.crane.mechanism.joint_to_stroke_partials` with dx0/dLc0 = dx0/dLc = 1 added back).
A direct actuator's column is ``retracted_length + x`` (its EMLA data), x its joint.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ClosedChain, Crane, LinkLengths
from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.errors import InvalidInputError

#: Decision variables per chain in Xi: (L, Lc0, Lc).
PER_CHAIN = 3


@dataclass(frozen=True)
class Actuator:
    """One actuator: its name, its column in joint/actuator samples and its chain (None: direct)."""

    name: str
    column: int
    chain: ClosedChain | None

    @property
    def xi_slice(self) -> slice:
        """Its chain's (L, Lc0, Lc) in Xi; empty for a direct actuator."""
        if self.chain is None:
            return slice(0, 0)
        return slice(PER_CHAIN * self.column, PER_CHAIN * self.column + PER_CHAIN)


def actuators(crane: Crane) -> tuple[Actuator, ...]:
    """The crane's actuators in sample order: one per chain, then the direct ones."""
    chain_names = tuple(chain.name for chain in crane.chains)
    if ACTUATOR_NAMES[: len(chain_names)] != chain_names:
        raise InvalidInputError(
            "chains", list(chain_names), f"must name the first actuators {list(ACTUATOR_NAMES)}, in order"
        )
    out = [Actuator(chain.name, k, chain) for k, chain in enumerate(crane.chains)]
    out += [Actuator(name, k, None) for k, name in enumerate(ACTUATOR_NAMES) if k >= len(chain_names)]
    return tuple(out)


def n_xi(crane: Crane) -> int:
    """Number of link-length variables Xi [-]."""
    return PER_CHAIN * len(crane.chains)


def column_length(
    crane: Crane,
    lengths: LinkLengths,
    actuator: Actuator,
    position: ArrayLike,
    retracted_length: float | None = None,
) -> tuple[Array, Array, Array]:
    """Column length s [m] of one actuator at joint samples, ds/d(its joint) and ds/dXi.

    Args:
        crane: The crane.
        lengths: Link lengths Xi [m].
        actuator: One of :func:`actuators`.
        position: Joint samples (T, n_joints) [rad or m].
        retracted_length: Column length at zero stroke of a direct actuator [m] (required then).

    Returns:
        s (T,) [m], ds/dq of the actuator's own joint (T,) [m/rad or -], ds/dXi (T, n_xi) [-].

    """
    q = np.asarray(position, dtype=float)[:, actuator.column]
    d_xi = np.zeros((q.shape[0], n_xi(crane)))
    if actuator.chain is None:
        if retracted_length is None:
            raise InvalidInputError(f"{actuator.name}.screw.retracted_length", None, "a direct actuator needs it", "m")
        return retracted_length + q, np.ones_like(q), d_xi
    xi = getattr(lengths, actuator.chain.name)
    x = mechanism.joint_to_stroke(actuator.chain, xi, q)
    d_theta, d_lengths = mechanism.joint_to_stroke_partials(actuator.chain, xi, q)
    d_xi[:, actuator.xi_slice] = d_lengths + np.array([0.0, 1.0, 1.0])
    return x + xi.x0, d_theta, d_xi

"""Feasible link-length sets for the MJCF and MuJoCo-ID tests (shared test helper, not a test module)."""

from __future__ import annotations

import numpy as np

from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ChainLengths, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.crane.mechanism import check_lengths

CRANE = load_crane("xs031")


def feasible_lengths(u: np.ndarray) -> LinkLengths:
    """Map u in [0, 1]^6 to a link-length set that serves both working joint ranges (check_lengths passes).

    Per chain: L from u[0] (lift 0.9..1.3, tilt 1.02..1.3 of the default: a shorter tilt L needs more
    than the 0.59 m stroke); the pin-to-pin length x0 inside [s(theta_max) - stroke, s(theta_min)], the
    interval that keeps the stroke in [0, stroke] over the range, and above stroke + 0.04 m; Lc from u[2]
    in [stroke, x0 - 0.02] (const_j: stroke <= Lc; Lc0 = x0 - Lc > 0).
    """
    chains = []
    for chain, (a, b, c), low in zip(CRANE.chains, np.reshape(u, (2, 3)), (0.9, 1.02), strict=True):
        L = chain.default_lengths.L * (low + (1.3 - low) * a)
        s = mechanism.stroke_from_hinge_angle(
            mechanism.hinge_angle(chain, np.array(chain.joint_range)), L, chain.L1, 0.0
        )
        lowest = max(s[1] - chain.stroke, chain.stroke + 0.04)
        x0 = lowest + (s[0] - lowest) * (0.02 + 0.96 * b)
        Lc = chain.stroke + (x0 - 0.02 - chain.stroke) * c
        chains.append(ChainLengths(L, x0 - Lc, Lc))
    lengths = LinkLengths(*chains)
    check_lengths(CRANE, lengths)
    return lengths

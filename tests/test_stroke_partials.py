"""The stroke's partials w.r.t. the joint angle and the link lengths (crane.mechanism) against finite differences."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ChainLengths
from hiab_sim.crane.loader import load_crane

CRANE = load_crane()


def _stroke(chain_index: int, xi: np.ndarray, theta: float) -> float:
    chain = CRANE.chains[chain_index]
    return float(mechanism.joint_to_stroke(chain, ChainLengths(*xi), theta))


@settings(max_examples=40, deadline=None)
@given(chain_index=st.sampled_from([0, 1]), fraction=st.floats(0.05, 0.95), scale=st.floats(0.9, 1.15))
def test_stroke_partials_match_central_differences(chain_index: int, fraction: float, scale: float) -> None:
    """dx/dtheta and dx/d(L, Lc0, Lc) equal central differences of joint_to_stroke inside the joint range."""
    chain = CRANE.chains[chain_index]
    built = getattr(CRANE.default_lengths, chain.name)
    xi = np.array([built.L * scale, built.Lc0, built.Lc])
    lo, hi = chain.joint_range
    theta = lo + fraction * (hi - lo)
    d_theta, d_lengths = mechanism.joint_to_stroke_partials(chain, ChainLengths(*xi), np.array([theta]))
    h = 1e-6
    fd_theta = (_stroke(chain_index, xi, theta + h) - _stroke(chain_index, xi, theta - h)) / (2 * h)
    assert abs(d_theta[0] - fd_theta) <= 1e-7 * max(1.0, abs(fd_theta))
    for i in range(3):
        up, down = xi.copy(), xi.copy()
        up[i] += h
        down[i] -= h
        fd = (_stroke(chain_index, up, theta) - _stroke(chain_index, down, theta)) / (2 * h)
        assert abs(d_lengths[0, i] - fd) <= 1e-7 * max(1.0, abs(fd))


def test_stroke_rate_is_minus_the_inverse_velocity_ratio() -> None:
    """dx/dtheta = -1/k1 (eq. k1_3 with dtheta = -dq): the two derivations of the chain agree."""
    chain = CRANE.lift
    lengths = CRANE.default_lengths.lift
    theta = np.linspace(*chain.joint_range, 7)[1:-1]
    d_theta, _ = mechanism.joint_to_stroke_partials(chain, lengths, theta)
    x = mechanism.joint_to_stroke(chain, lengths, theta)
    k1, _, _ = mechanism.velocity_ratios(x, lengths.L, chain.L1, lengths.x0)
    np.testing.assert_allclose(d_theta, -1.0 / k1, rtol=1e-12)

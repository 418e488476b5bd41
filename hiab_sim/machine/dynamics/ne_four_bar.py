"""Closure of the four-bars of a machine's linkage chains, for the Newton-Euler solve.

The rocker (hinged at J) and the coupler (hinged on it at H, |H - J| = r_1) close at the coupler
pivot K, |K - H| = r_2: H is the intersection of the two circles on side ``pin_side`` of J -> K
(:mod:`hiab_sim.machine.dynamics.planar`). With a = H - J and b = K - H,

    v_K - v_J = i omega_r a + i omega_c b

dotted with b and a gives omega_r = (b . v) / (a x b), omega_c = -(a . v) / (a x b), and the same
for the accelerations less the centripetal terms, alpha_r = (b . rest) / (a x b),
alpha_c = -(a . rest) / (a x b) with rest = a_K - a_J + omega_r^2 a + omega_c^2 b. Arrays as in
:mod:`hiab_sim.machine.dynamics.ne_workspace`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.ne_workspace import Prepared, Workspace

Complex = NDArray[np.complex128]


def four_bars(ws: Workspace, pc: Prepared, angles: bool) -> Complex:
    """Rocker and coupler frames (and with ``angles`` their coordinates); the rod pins H's motion (3, n, D, T).

    Raises:
        InvalidInputError: a four-bar that cannot close (field ``chains.<chain>.linkage``).

    """
    layout = ws.layout
    g = layout.groups
    n = len(g.bar_chain)
    J, K = ws.c("four-bar J", 3, n), ws.c("four-bar K", 3, n)
    spare = (ws.c("four-bar arm", n), ws.c("four-bar spare", 3, n))
    ws.points(g.bar_j, pc.bar_j, J, spare)
    ws.points(g.bar_k, pc.bar_k, K, spare)
    r1, r2, side = (x[:, None, None] for x in (g.bar_r1, g.bar_r2, g.bar_side))
    span = np.abs(K[0] - J[0])
    along = (span * span + r1 * r1 - r2 * r2) / (2.0 * span)
    height2 = r1 * r1 - along * along
    if np.any(height2 < 0.0):
        k = int(np.argmax(np.any(height2 < 0.0, axis=(1, 2))))
        low, high = abs(g.bar_r1[k] - g.bar_r2[k]), g.bar_r1[k] + g.bar_r2[k]
        raise InvalidInputError(
            f"chains.{g.bar_names[k]}.linkage", f"|K - J| = {float(span[k][height2[k] < 0.0][0]):.6g} m",
            f"must lie in [{low:.6g}, {high:.6g}] for the four-bar to close", "m",
        )  # fmt: skip
    H = J[0] + (K[0] - J[0]) / span * (along + 1j * side * np.sqrt(height2))
    arm, reach = H - J[0], K[0] - H  # rocker J -> H, coupler H -> K
    v, a = K[1] - J[1], K[2] - J[2]
    turn = arm.real * reach.imag - arm.imag * reach.real  # a x b
    w_r = (reach.real * v.real + reach.imag * v.imag) / turn
    w_c = -(arm.real * v.real + arm.imag * v.imag) / turn
    rest = a + w_r * w_r * arm + w_c * w_c * reach
    a_r = (reach.real * rest.real + reach.imag * rest.imag) / turn
    a_c = -(arm.real * rest.real + arm.imag * rest.imag) / turn
    rocker, coupler, link = g.bar_rocker, g.bar_coupler, g.bar_j
    factor = ws.c("four-bar factor", 3, n)
    ws.orient(rocker, arm / r1 * layout.unturn[rocker][:, None, None], w_r, a_r, factor)
    ws.motion[:, rocker] = J
    ws.orient(coupler, reach / r2 * layout.unturn[coupler][:, None, None], w_c, a_c, factor)
    H_motion = np.stack([H, J[1] + 1j * w_r * arm, J[2] + (1j * a_r - w_r * w_r) * arm])
    ws.motion[:, coupler] = H_motion
    if angles:
        ws.q[rocker] = np.angle(ws.rot[rocker] * ws.rot[link].conj())
        ws.dq[rocker], ws.ddq[rocker] = w_r - ws.omega[link], a_r - ws.alpha[link]
        ws.q[coupler] = np.angle(reach * arm.conj())
        ws.dq[coupler], ws.ddq[coupler] = w_c - w_r, a_c - a_r
    return H_motion

"""Partials of the actuator stroke with respect to a chain's decision variables, at fixed joint values.

For the NLP's analytic design derivatives (the generic counterpart of
:func:`hiab_sim.crane.mechanism.joint_to_stroke_partials`). With x = s(q; pivots) - x0:

* ``piston_offset``, ``rod_length``, ``retracted_length``: dx/dv = -1 (x0 = Lc0 + Lc grows by dv);
* a pivot moved by dv along a direction d of its link frame (``pivot_x``: (1, 0); ``pivot_y``:
  (0, 1); ``hinge_distance``: the unit vector from the hinge to the pivot), d_P = d in the frame P
  of the driven joint's parent, or Rz(phi + q) d for a pivot on the driven link. Triangle,
  v = end - base: ds/dv = (v/s).(d_end - d_base). Linkage: the pin H moves by dH with
  (H - r).dH = (H - r).d_r and (H - C).dH = (H - C).d_C (the two circle equations), and
  ds/dv = ((H - b)/s).(dH - d_b).

Vectorised over joint samples; m per m (dimensionless).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.machine.description import Chain, DecisionVariable, Machine
from hiab_sim.machine.kinematics.closure import ChainGeometry, chain_geometry, length_and_rate


def pivot_direction(machine: Machine, chain: Chain, variable: DecisionVariable) -> Array:
    """Unit motion of the pivot per unit of the variable, in the pivot's link frame (x, y)."""
    if variable.kind == "pivot_x":
        return np.array([1.0, 0.0])
    if variable.kind == "pivot_y":
        return np.array([0.0, 1.0])
    pivot = chain.pivot(str(variable.pivot))
    arm = pivot.xy - machine.hinge_xy(chain, pivot.link)
    return arm / np.linalg.norm(arm)


def stroke_design_partials(machine: Machine, chain: Chain, q: ArrayLike) -> tuple[Array, Array]:
    """(dx/dq, dx/dv) at joint samples q: dx/dv has shape (*q.shape, len(chain.variables))."""
    q = np.asarray(q, dtype=float)
    geo = chain_geometry(machine, chain)
    c = length_and_rate(geo, q)
    out = np.zeros((*q.shape, len(chain.variables)))
    driven = machine.joint_link(chain.joint).name
    angle = geo.phi + q
    cos, sin = np.cos(angle), np.sin(angle)
    if chain.kind == "linkage":
        H, C = c.pin, c.coupler_pivot
        assert H is not None and C is not None
        unit = (H - geo.fixed["base"]) / c.length[..., None]
        hr, hc = H - geo.fixed["rocker"], H - C
    elif chain.kind == "triangle":
        base, end = (_pivot_in_parent(geo, role, cos, sin) for role in ("base", "end"))
        unit = (end - base) / c.length[..., None]
    for k, variable in enumerate(chain.variables):
        if variable.kind in ("piston_offset", "rod_length", "retracted_length"):
            out[..., k] = -1.0
            continue
        pivot = chain.pivot(str(variable.pivot))
        d = pivot_direction(machine, chain, variable)
        if pivot.link == driven:
            d_p = np.stack([cos * d[0] - sin * d[1], sin * d[0] + cos * d[1]], axis=-1)
        else:
            d_p = np.broadcast_to(d, (*q.shape, 2))
        if chain.kind == "triangle":
            sign = 1.0 if pivot.role == "end" else -1.0
            out[..., k] = sign * np.einsum("...i,...i->...", unit, d_p)
            continue
        zero = np.zeros(q.shape)
        rhs_r = np.einsum("...i,...i->...", hr, d_p) if pivot.role == "rocker" else zero
        rhs_c = np.einsum("...i,...i->...", hc, d_p) if pivot.role == "coupler" else zero
        det = hr[..., 0] * hc[..., 1] - hr[..., 1] * hc[..., 0]
        dH = np.stack(
            [(rhs_r * hc[..., 1] - rhs_c * hr[..., 1]) / det, (hr[..., 0] * rhs_c - hc[..., 0] * rhs_r) / det], -1
        )
        move = dH - d_p if pivot.role == "base" else dH
        out[..., k] = np.einsum("...i,...i->...", unit, move)
    return c.length_dq, out


def _pivot_in_parent(geo: ChainGeometry, role: str, cos: Array, sin: Array) -> Array:
    """A triangle pivot's position in the parent frame P at the joint samples."""
    if role in geo.fixed:
        return np.broadcast_to(geo.fixed[role], (*cos.shape, 2))
    local = geo.moving[role]
    return geo.hinge + np.stack([cos * local[0] - sin * local[1], sin * local[0] + cos * local[1]], axis=-1)

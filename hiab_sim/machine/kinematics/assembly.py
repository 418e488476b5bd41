"""Assembly of a machine over its working ranges: usable and reachable ranges, and what fails.

A chain serves a joint sample q when (i) its loop closes (:attr:`Closure.closes`); (ii) it does
not pass a toggle: ds/dq keeps the sign it has at the middle of the working range (s' = 0 is
the flat triangle of seed eq. k1_3, sin q = 0, or the actuator in line with the rocker), and
for a linkage the four-bar's transmission (the cross product of H - r and H - C) keeps its sign;
(iii) its stroke x = s - x0 lies in the usable stroke [0, min(stroke, Lc)] (seed const_j: the
rod cannot extend past its length). The reachable joint range is the largest interval around
the middle of the working range where all three hold; :func:`check_machine` lists, one entry
each, every chain whose working range leaves it, and a TCP that leaves the declared workspace.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Chain, Machine
from hiab_sim.machine.kinematics.closure import (
    ChainGeometry,
    chain_geometry,
    geometry_closure,
    pin_position,
    stroke_to_joint,
)
from hiab_sim.machine.kinematics.forward import forward_kinematics

#: Slack on stroke bounds [m] against round-off at the ends of a range computed from them.
STROKE_TOLERANCE = 1e-12
#: Samples of each working range that :func:`check_machine` assembles.
CHECK_SAMPLES = 401


@dataclass(frozen=True)
class Failure:
    """One thing that fails: the field, what it is and what is allowed (an :class:`InvalidInputError`'s parts)."""

    field: str
    value: object
    allowed: str
    unit: str = ""

    def error(self) -> InvalidInputError:
        """The failure as the error a loader raises."""
        return InvalidInputError(self.field, self.value, self.allowed, self.unit)

    def __str__(self) -> str:
        return str(self.error())


def usable_stroke(chain: Chain) -> tuple[float, float]:
    """Usable stroke [0, min(stroke, Lc)] [m] (seed const_j; a direct actuator: [0, stroke])."""
    act = chain.actuator
    top = act.stroke if act.rod_length is None or chain.kind == "direct" else min(act.stroke, act.rod_length)
    return (0.0, top)


def _transmission(geo: ChainGeometry, q: Array) -> Array:
    """Sign-carrying transmission of a linkage: cross(H - r, H - C) (zero at the four-bar's toggle)."""
    with np.errstate(invalid="ignore"):  # NaN where the loop does not close
        H, C, _, _ = pin_position(geo, q)
        a, b = H - geo.fixed["rocker"], H - C
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _serves(geo: ChainGeometry, chain: Chain, q: Array, reference: float) -> NDArray[np.bool_]:
    """Where the chain serves q (the three conditions of the module docstring)."""
    c = geometry_closure(geo, q)
    ref = geometry_closure(geo, np.array(reference))
    ok = c.closes & (np.sign(c.length_dq) == np.sign(ref.length_dq)) & (c.length_dq != 0.0)
    if geo.kind == "linkage":
        ok &= np.sign(_transmission(geo, q)) == np.sign(_transmission(geo, np.array(reference)))
    x = c.length - geo.x0
    low, high = usable_stroke(chain)
    with np.errstate(invalid="ignore"):
        ok &= (x >= low - STROKE_TOLERANCE) & (x <= high + STROKE_TOLERANCE)
    return ok & np.isfinite(x)


def working_range(machine: Machine, chain: Chain) -> tuple[float, float]:
    """The working range of the joint the chain drives [rad or m]."""
    interval = machine.joint_link(chain.joint).joint_range
    assert interval is not None  # a chain drives a moving joint (Machine validates it)
    return interval


def reachable_joint_range(machine: Machine, chain: Chain) -> tuple[float, float] | None:
    """Largest joint interval around the working range's middle that the chain serves, or None.

    Found by stepping outwards from the middle (revolute: up to pi each way in 4000 steps;
    direct: the usable stroke) and bisecting each end to round-off; an end set by a stroke limit
    is then recomputed by the closed-form inverse closure.
    """
    geo = chain_geometry(machine, chain)
    if chain.kind == "direct":
        return usable_stroke(chain)
    middle = 0.5 * sum(working_range(machine, chain))
    if not _serves(geo, chain, np.array([middle]), middle)[0]:
        return None
    steps = np.linspace(0.0, np.pi, 4001)[1:]
    ends = []
    for direction in (-1.0, 1.0):
        q = middle + direction * steps
        ok = _serves(geo, chain, q, middle)
        if np.all(ok):
            ends.append(float(q[-1]))
            continue
        first_bad = int(np.argmin(ok))
        good = middle if first_bad == 0 else float(q[first_bad - 1])
        bad = float(q[first_bad])
        for _ in range(80):
            mid = 0.5 * (good + bad)
            if mid in (good, bad):
                break
            if _serves(geo, chain, np.array([mid]), middle)[0]:
                good = mid
            else:
                bad = mid
        ends.append(_snap_to_stroke_end(machine, chain, geo, good))
    return (ends[0], ends[1])


def _snap_to_stroke_end(machine: Machine, chain: Chain, geo: ChainGeometry, q: float) -> float:
    """An end bisected to a stroke limit, recomputed exactly by the inverse closure (no tolerance slack)."""
    x = float(geometry_closure(geo, np.array(q)).length) - geo.x0
    for limit in usable_stroke(chain):
        if abs(x - limit) < 1e-9:
            return float(stroke_to_joint(machine, chain, np.array(limit)))
    return q


def _chain_failures(machine: Machine, chain: Chain) -> list[Failure]:
    geo = chain_geometry(machine, chain)
    low, high = working_range(machine, chain)
    where = f"chains.{chain.name}"
    q = np.linspace(low, high, CHECK_SAMPLES)
    c = geometry_closure(geo, q)
    unit = "m" if chain.kind == "direct" else "rad"
    if not np.all(c.closes):
        bad = float(q[np.argmin(c.closes)])
        return [Failure(where, f"{chain.joint} = {bad:.6g} {unit}", "loop does not close there (a side too short)")]
    out = []
    sign = np.sign(c.length_dq)
    toggled = bool(np.any(sign != sign[CHECK_SAMPLES // 2]) or np.any(c.length_dq == 0.0))
    if geo.kind == "linkage":
        t = np.sign(_transmission(geo, q))
        toggled = toggled or bool(np.any(t != t[CHECK_SAMPLES // 2]))
    if toggled:
        reach = reachable_joint_range(machine, chain)
        shown = "none" if reach is None else f"[{reach[0]:.6g}, {reach[1]:.6g}] {unit}"
        out.append(
            Failure(
                f"links.{machine.joint_link(chain.joint).name}.joint_range",
                f"[{low:.6g}, {high:.6g}]",
                f"chain {chain.name} passes its toggle inside it; reachable without toggling: {shown}",
                unit,
            )
        )
    x = c.length - geo.x0
    top = usable_stroke(chain)[1]
    if x.min() < -STROKE_TOLERANCE or x.max() > top + STROKE_TOLERANCE:
        out.append(
            Failure(
                f"{where}.actuator.stroke",
                chain.actuator.stroke,
                f"the working range needs x in [{x.min():.6g}, {x.max():.6g}] m from the retracted length "
                f"{geo.x0:.6g} m; usable [0, {top:.6g}] m (stroke, rod length)",
                "m",
            )
        )
    return out


def _workspace_failures(machine: Machine) -> list[Failure]:
    if machine.workspace is None:
        return []
    tcp = tcp_samples(machine, 9)
    (x_low, x_high), (y_low, y_high) = machine.workspace
    outside = (tcp[:, 0] < x_low) | (tcp[:, 0] > x_high) | (tcp[:, 1] < y_low) | (tcp[:, 1] > y_high)
    if not np.any(outside):
        return []
    p = tcp[np.argmax(outside)]
    return [
        Failure(
            "workspace",
            f"TCP at ({p[0]:.6g}, {p[1]:.6g})",
            f"the working ranges take the TCP outside x in [{x_low:.6g}, {x_high:.6g}], "
            f"y in [{y_low:.6g}, {y_high:.6g}]",
            "m",
        )
    ]


def joint_grid(machine: Machine, per_joint: int) -> Array:
    """Every combination of ``per_joint`` samples of each joint's working range, (N, n_joints)."""
    axes = []
    for joint in machine.joint_names:
        low, high = machine.joint_link(joint).joint_range or (0.0, 0.0)
        axes.append(np.linspace(low, high, per_joint))
    return np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, len(axes))


def tcp_samples(machine: Machine, per_joint: int) -> Array:
    """TCP world positions (N, 3) over :func:`joint_grid` [m]."""
    return forward_kinematics(machine, joint_grid(machine, per_joint)).tcp_position


def check_machine(machine: Machine) -> list[Failure]:
    """Every failure of the machine's assembly over its working ranges (empty: it assembles)."""
    out: list[Failure] = []
    for chain in machine.chains:
        out.extend(_chain_failures(machine, chain))
    if not out:
        out.extend(_workspace_failures(machine))
    return out

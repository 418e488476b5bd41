"""Shared pieces of the MJCF import: a value with its MJCF origin, the import's content, plane coordinates.

Conventions and units in :mod:`hiab_sim.machine.mjcf_import.importer`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.machine.mjcf_import.graph import Mechanism, connect_points, name_of
from hiab_sim.machine.mjcf_import.pose import plane_axes
from hiab_sim.machine.parts import rot_z


@dataclass(frozen=True)
class Note:
    """A value and where in the MJCF it came from (the YAML comment)."""

    value: Any
    origin: str


@dataclass
class Imported:
    """The machine file's content and what the round trip needs to map machine states onto the MJCF.

    ``joint_map``: per machine joint, (MJCF joint id, a, b) with q = a qpos + b; ``actuators``: per
    chain, (MJCF slide joint id, kappa) with the generalised slide force Q = kappa f_x; ``tcp``:
    (body id, point in its body frame [m]).
    """

    mech: Mechanism
    tree: dict[str, Any]
    qpos_ref: Array
    joint_map: list[tuple[int, float, float]] = field(default_factory=list)
    actuators: list[tuple[int, float]] = field(default_factory=list)
    tcp: tuple[int, Array] = (0, np.zeros(3))
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # what the import leaves aside or suspects (import_warnings)


class Frames:
    """Machine-plane coordinates of MuJoCo world quantities at the reference pose."""

    def __init__(self, mech: Mechanism, data: mujoco.MjData) -> None:
        self.mech, self.data = mech, data
        self.axes = plane_axes(mech)

    def point(self, p: Array) -> Array:
        """A world point or vector in machine-plane coordinates [m]."""
        return self.axes.T @ np.asarray(p, dtype=float)

    def edge_point(self, k: int, group: int) -> Array:
        """Machine coordinates of an edge's pin (a hinge's anchor, a connect's anchor on ``group``)."""
        edge, model = self.mech.edges[k], self.mech.model
        if edge.kind != "pin":
            return self.point(self.data.xanchor[edge.index])
        p1, p2 = connect_points(model, self.data, edge.index)
        b1 = int(model.eq_obj1id[edge.index])
        if model.eq_objtype[edge.index] == mujoco.mjtObj.mjOBJ_SITE:
            b1 = int(model.site_bodyid[b1])
        return self.point(p1 if self.mech.group_of_body[b1] == group else p2)

    def bodies(self, group: int, origin: Array, angle: float, prefix: str = "") -> dict[str, Note]:
        """Each massive MJCF body of a group in the frame (origin, Rz(angle)) of machine coordinates."""
        model, d = self.mech.model, self.data
        rot = np.array(rot_z(angle))
        out: dict[str, Note] = {}
        for b in self.mech.bodies(group):
            if model.body_mass[b] <= 0.0:
                continue
            xi = d.ximat[b].reshape(3, 3)
            inertia_world = xi @ np.diag(model.body_inertia[b]) @ xi.T
            inertia = rot.T @ self.axes.T @ inertia_world @ self.axes @ rot
            inertia = 0.5 * (inertia + inertia.T)
            com = rot.T @ (self.point(d.xipos[b]) - origin)
            bname = name_of(model, mujoco.mjtObj.mjOBJ_BODY, b, "body")
            origin_text = f"body '{bname}': mass, centre of mass and inertia (compiled)"
            eig = np.linalg.eigvalsh(inertia)
            gap = eig[2] * (1.0 + 1e-9) - eig[0] - eig[1]
            if gap > 0.0:  # a flat body (A + B = C) rounded below MuJoCo's bound: lift Ixx, Iyy
                inertia[0, 0] += gap
                inertia[1, 1] += gap
                origin_text += f"; Ixx, Iyy + {gap:.3g} (out-of-plane moments, no planar effect) for A + B >= C"
            value = {"mass": float(model.body_mass[b]), "com": _list(com), "inertia": [_list(r) for r in inertia]}
            out[prefix + bname] = Note(value, origin_text)
        return out


def _list(v: Array) -> list[float]:
    """Floats, round-off below 1e-13 m (or kg m^2) written as 0."""
    return [0.0 if abs(float(x)) < 1e-13 else float(x) for x in v]

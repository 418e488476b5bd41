"""MJCF with closed loops -> machine description (``hiab-sim machine import``), every value with its MJCF origin.

:func:`import_mjcf` reads the file with MuJoCo's compiler, finds the plane, the groups and the
closed chains (:mod:`hiab_sim.machine.mjcf_import_graph`), closes the loops at a reference pose
(the first keyframe or ``qpos0`` whose ``connect`` pins close, else Newton from ``qpos0``:
:mod:`hiab_sim.machine.mjcf_import_pose`) and writes, at that pose:

* **frames**: the machine's world is the plane (x, y up = against gravity, z the normal); the root
  link ``world`` holds the world body and every body welded or locked to it; a link driven by a
  hinge has its frame at the hinge anchor, turned with the joint (q = +-qpos: the sign of the
  hinge axis along the normal); a prismatic link has its frame at the slide anchor, x along the
  slide (q = qpos - range[0], so the stroke starts at 0);
* **chains**: a triangle's base pivot is where the actuator's parent-side body is pinned, the end
  pivot where the other is; a four-bar's base, rocker and coupler pivots are the actuator's base
  pin and the rocker's and coupler's pins; the retracted length x0 and stroke come from the slide's
  range; the rod length Lc is the rod body's origin to its pin along the actuator (Lc0 = x0 - Lc);
* **bodies**: each MJCF body of a group, its mass, centre of mass and full inertia re-expressed in
  the group's machine frame (cylinder, rod, rocker and coupler frames as ``docs/machine.md``).

Lengths in m, angles in rad, masses in kg, inertias in kg m^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from hiab_sim.errors import ConfigError
from hiab_sim.machine.mjcf_import_graph import ClosedChain, Mechanism, UnsupportedMJCFError, connect_points, name_of
from hiab_sim.machine.mjcf_import_graph import read_mechanism as _read
from hiab_sim.machine.mjcf_import_pose import close, plane_axes, residual_and_jacobian

Array = NDArray[np.float64]

#: A pin's pose residual accepted as closed before Newton [m].
CLOSED_TOL = 1e-3
#: Bounds proposed around imported values: +-15 % for hinge distances, +-30 % for lengths, +-10 % x0 for pivots.
L_SPAN, LENGTH_SPAN, PIVOT_SPAN = 0.15, 0.30, 0.10


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


def load_model(path: str | Path) -> mujoco.MjModel:
    """Compile an MJCF file; a missing or malformed file raises a one-line :class:`ConfigError`."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"{path}: no such MJCF file")
    try:
        return mujoco.MjModel.from_xml_path(str(p))
    except ValueError as error:
        raise ConfigError(f"{path}: MuJoCo cannot compile it: {' '.join(str(error).split())}") from None


class _Frames:
    """Machine-plane coordinates of MuJoCo world quantities at the reference pose."""

    def __init__(self, mech: Mechanism, data: mujoco.MjData) -> None:
        self.mech, self.data = mech, data
        self.axes = plane_axes(mech)

    def point(self, p: Array) -> Array:
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
        rot = _rz(angle)
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


def _rz(angle: float) -> Array:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _list(v: Array) -> list[float]:
    """Floats, round-off below 1e-13 m (or kg m^2) written as 0."""
    return [0.0 if abs(float(x)) < 1e-13 else float(x) for x in v]


def _angle(v: Array) -> float:
    return math.atan2(float(v[1]), float(v[0]))


def _reference_pose(mech: Mechanism, dependent: list[int]) -> tuple[mujoco.MjData, str]:
    """Data at a loop-consistent pose: a keyframe or qpos0 whose pins close, else Newton from qpos0."""
    model = mech.model
    data = mujoco.MjData(model)
    starts = [
        (model.key_qpos[k], f"keyframe '{name_of(model, mujoco.mjtObj.mjOBJ_KEY, k, 'key')}'")
        for k in range(model.nkey)
    ]
    starts.append((model.qpos0, "qpos0 (the joints' ref)"))
    for qpos, label in [*starts, (model.qpos0, "Newton from qpos0")]:
        data.qpos[:] = qpos
        for j, value in mech.locked.items():
            data.qpos[model.jnt_qposadr[j]] = value
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        residual, _ = residual_and_jacobian(mech, data)
        if label.startswith("Newton") or (residual.size == 0 or np.max(np.abs(residual)) < CLOSED_TOL):
            if close(mech, data, dependent) < 1e-10:
                return data, label
    raise UnsupportedMJCFError(["model: no loop-consistent pose found (no keyframe or qpos0 closes the connects)"])


def _range(model: mujoco.MjModel, j: int, what: str) -> tuple[float, float]:
    jname = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
    if not model.jnt_limited[j]:
        raise UnsupportedMJCFError([f"joint '{jname}': {what} needs a range (range=\"min max\")"])
    return float(model.jnt_range[j, 0]), float(model.jnt_range[j, 1])


def import_mjcf(
    path: str | Path, tcp: str | None = None, locks: dict[str, float] | None = None, plane: str = "auto"
) -> Imported:
    """Read an MJCF into machine-file content (see the module docstring).

    Raises:
        ConfigError: a missing or malformed file.
        UnsupportedMJCFError: one line per construct the machine format cannot represent.

    """
    model = load_model(path)
    mech = _read(model, locks or {}, plane)
    from hiab_sim.machine.mjcf_import_chains import chain_roles, write_tree

    roles = chain_roles(mech)
    dependent = [int(model.jnt_dofadr[mech.edges[k].index]) for r in roles for k in r.own_edges]
    data, pose = _reference_pose(mech, dependent)
    frames = _Frames(mech, data)
    imported = Imported(mech, {}, data.qpos.copy())
    imported.notes.append(f"reference pose: {pose}")
    write_tree(imported, frames, roles, tcp, Path(path).name)
    return imported


__all__ = ["ClosedChain", "Imported", "Note", "UnsupportedMJCFError", "import_mjcf", "load_model"]

"""MJCF with closed loops -> machine description (``hiab-sim machine import``), every value with its MJCF origin.

:func:`import_mjcf` reads the file with MuJoCo's compiler, finds the plane, the groups and the
closed chains (:mod:`hiab_sim.machine.mjcf_import.graph`), closes the loops at a reference pose
(the first keyframe or ``qpos0`` whose ``connect`` pins close, else Newton from ``qpos0``:
:mod:`hiab_sim.machine.mjcf_import.pose`) and writes, at that pose:

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

from pathlib import Path

import mujoco
import numpy as np

from hiab_sim.errors import ConfigError
from hiab_sim.machine.mjcf_import.chains import chain_roles
from hiab_sim.machine.mjcf_import.frames import Frames, Imported, Note
from hiab_sim.machine.mjcf_import.graph import ClosedChain, Mechanism, UnsupportedMJCFError, name_of
from hiab_sim.machine.mjcf_import.graph import read_mechanism as _read
from hiab_sim.machine.mjcf_import.import_warnings import degree_trap, terms_left_aside
from hiab_sim.machine.mjcf_import.pose import close, residual_and_jacobian
from hiab_sim.machine.mjcf_import.tree import write_tree

#: A pin's pose residual accepted as closed before Newton [m].
CLOSED_TOL = 1e-3
#: Bounds proposed around imported values: +-15 % for hinge distances, +-30 % for lengths, +-10 % x0 for pivots.
L_SPAN, LENGTH_SPAN, PIVOT_SPAN = 0.15, 0.30, 0.10


def load_model(path: str | Path) -> mujoco.MjModel:
    """Compile an MJCF file; a missing or malformed file raises a one-line :class:`ConfigError`."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"{path}: no such MJCF file")
    try:
        return mujoco.MjModel.from_xml_path(str(p))
    except ValueError as error:
        raise ConfigError(f"{path}: MuJoCo cannot compile it: {' '.join(str(error).split())}") from None


def _reference_pose(mech: Mechanism, dependent: list[int]) -> tuple[mujoco.MjData, str]:
    """Data at a loop-consistent pose: a keyframe or qpos0 whose pins close, else Newton from qpos0."""
    model = mech.model
    data = mujoco.MjData(model)
    starts = [
        (model.key_qpos[k], f"keyframe '{name_of(model, mujoco.mjtObj.mjOBJ_KEY, k, 'key')}'")
        for k in range(model.nkey)
    ]
    starts.append((model.qpos0, "qpos0 (the joints' ref)"))
    skipped: list[str] = []  # keyframes whose pins do not close, said in the file's header
    for qpos, label in [*starts, (model.qpos0, "Newton from qpos0")]:
        data.qpos[:] = qpos
        for j, value in mech.locked.items():
            data.qpos[model.jnt_qposadr[j]] = value
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        residual, _ = residual_and_jacobian(mech, data)
        gap = float(np.max(np.abs(residual))) if residual.size else 0.0
        if label.startswith("Newton") or gap < CLOSED_TOL:
            if close(mech, data, dependent) < 1e-10:
                return data, "; ".join([label, *skipped])
        elif label.startswith("keyframe"):
            skipped.append(
                f"{label} skipped: its connect pins are up to {gap:.3g} m apart (MuJoCo places a connect's "
                "second anchor where the first is at qpos0)"
            )
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
    roles = chain_roles(mech)
    dependent = [int(model.jnt_dofadr[mech.edges[k].index]) for r in roles for k in r.own_edges]
    data, pose = _reference_pose(mech, dependent)
    frames = Frames(mech, data)
    imported = Imported(mech, {}, data.qpos.copy())
    imported.notes.append(f"reference pose: {pose}")
    imported.warnings += [*degree_trap(path, mech), *terms_left_aside(mech)]
    write_tree(imported, frames, roles, tcp, Path(path).name)
    return imported


__all__ = ["ClosedChain", "Imported", "Note", "UnsupportedMJCFError", "import_mjcf", "load_model"]

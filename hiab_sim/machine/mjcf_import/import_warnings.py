"""What an MJCF import leaves aside or suspects, told the user: the degree trap and the joint terms left aside.

* **Degree trap.** MuJoCo reads a hinge's ``range`` in degrees unless the file says
  ``<compiler angle="radian"/>`` (its default is ``degree``): a range written in radians in such a file,
  ``range="0 1.1"``, compiles to [0, 0.0192] rad. A driven hinge of a heavy machine whose working range
  spans less than :data:`NARROW_RANGE_RAD` in a degree-mode file is named, with the range it got and
  the one it would have had in radians. The import does not change it (it follows MuJoCo, as
  documented): only the user knows what was meant.
* **Joint terms left aside.** The machine format holds the mechanism; a machine joint's stiffness,
  damping, armature and friction loss in the MJCF are not imported (the EMLA model adds its own rotor
  inertia and friction): each joint with any of them is named with their values, so that a model
  tuned with them is not silently simulated without.

Each warning is one line, written into the machine file's header and printed by ``hiab-sim machine
import``.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco

from hiab_sim.machine.mjcf_import.graph import Mechanism, name_of

#: A driven hinge's working range narrower than this [rad] (2.9 deg) in a degree-mode file is named: booms and
#: buckets swing tens of degrees, and 0.05 rad is what a range of 2.9 written in radians compiles to in degrees.
NARROW_RANGE_RAD = 0.05

#: MJCF joint terms the machine format leaves aside: (label, model array, index by dof or by joint, unit).
_TERMS = (
    ("stiffness", "jnt_stiffness", "joint", "per rad or per m"),
    ("damping", "dof_damping", "dof", "per rad/s or per m/s"),
    ("armature", "dof_armature", "dof", "kg m^2 or kg"),
    ("frictionloss", "dof_frictionloss", "dof", "N m or N"),
)


def _degree_mode(path: str | Path) -> bool:
    """Whether the file's compiler reads angles in degrees (MuJoCo's default) by MuJoCo's own parser."""
    return bool(mujoco.MjSpec.from_file(str(path)).compiler.degree)


def degree_trap(path: str | Path, mech: Mechanism) -> list[str]:
    """One line per hinge whose range is narrower than :data:`NARROW_RANGE_RAD` in a file read in degrees."""
    if not _degree_mode(path):
        return []
    model, out = mech.model, []
    for edge in mech.edges:
        if edge.kind != "hinge" or not model.jnt_limited[edge.index]:
            continue
        low, up = (float(v) for v in model.jnt_range[edge.index])
        if up - low < NARROW_RANGE_RAD:
            name = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, edge.index, "joint")
            out.append(
                f"joint '{name}': range [{low:.4g}, {up:.4g}] rad ({math.degrees(up - low):.2f} deg wide): "
                "the file reads "
                f'angles in degrees (no <compiler angle="radian"/>); written in radians it would be '
                f"[{math.degrees(low):.4g}, {math.degrees(up):.4g}] rad"
            )
    return out


def terms_left_aside(mech: Mechanism) -> list[str]:
    """One line per machine joint with stiffness, damping, armature or friction loss in the MJCF (not imported)."""
    model, out = mech.model, []
    for edge in mech.edges:
        if edge.kind == "pin":
            continue
        j = edge.index
        indices = {"joint": j, "dof": int(model.jnt_dofadr[j])}
        given = [
            f"{label} {float(getattr(model, array)[indices[by]]):.4g} ({unit})"
            for label, array, by, unit in _TERMS
            if float(getattr(model, array)[indices[by]]) != 0.0
        ]
        if given:
            name = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
            out.append(f"joint '{name}': {', '.join(given)} left aside (not part of the machine format)")
    return out

"""The machine file's tree of an imported MJCF: links, chains and TCP, at the reference pose.

Conventions and units in :mod:`hiab_sim.machine.mjcf_import.importer`.
"""

from __future__ import annotations

import mujoco
import numpy as np

from hiab_sim.machine.mjcf_import.chains import Role
from hiab_sim.machine.mjcf_import.frames import Frames, Imported, Note
from hiab_sim.machine.mjcf_import.graph import actuator_on, name_of
from hiab_sim.machine.mjcf_import.parts import chain_entry, emla_note, link_entries, tcp_entry


def write_tree(imported: Imported, frames: Frames, roles: list[Role], tcp: str | None, filename: str) -> None:
    """Fill ``imported.tree`` (links, chains, tcp) and its maps, at the reference pose of ``frames``."""
    mech = imported.mech
    model = mech.model
    links, link_frames = link_entries(imported, frames, roles)
    chains = {}
    for role in roles:
        name, entry = chain_entry(imported, frames, role, link_frames)
        chains[name] = entry
    for k, edge in enumerate(mech.edges):
        if edge.kind == "slide" and not any(k in r.block.edges for r in roles):
            jname = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, edge.index, "joint")
            act = actuator_on(model, edge.index) or jname
            low, high = model.jnt_range[edge.index]
            imported.actuators.append((edge.index, 1.0))
            chains[act] = {
                "kind": Note("direct", f"{edge.element}: a slide outside every loop, its own actuator"),
                "joint": Note(jname, edge.element),
                "actuator": {
                    "stroke": Note(float(high - low), f"{edge.element} range [{low:g}, {high:g}]: max - min"),
                    "emla": emla_note(act),
                },
            }
    gravity = Note(mech.gravity, f"option gravity {np.round(model.opt.gravity, 9).tolist()}: its in-plane magnitude")
    imported.tree = {
        "name": Note(f"{filename} (imported)", "the MJCF file"),
        "source": Note(f"MJCF {filename} imported by hiab-sim machine import", "the MJCF file"),
        "gravity": gravity,
        "links": links,
        "chains": chains,
        "tcp": tcp_entry(imported, frames, link_frames, tcp),
    }

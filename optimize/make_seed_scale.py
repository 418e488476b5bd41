"""Geometric scaling of the XS 031 crane and its EMLAs to the seed paper's size.

The seed paper starts from xi1 = [1.75, 0.544, 1.27] and xi2 = [1.75, 0.55, 1.2] m on its own
HIAB crane, whose data is not public. ``seed_scale_spiral.yaml`` instead scales the public XS 031
geometry by s = 1.75 / L_lift(XS 031) (the seed's lift L fits exactly) with the rules:

* lengths x s (pivots, L, L1, Lc, Lc0, strokes, telescope, TCP offset, centres of mass);
* masses x s^3 (same density), inertias x s^5 (mass x length^2);
* joint angles unchanged; the scaled crane's working joint ranges are those the seed's start
  lengths reach (within each chain's stroke and triangle), so the seed's start is admissible;
* EMLAs: forces grow as s^3 and speeds as s on the same angular motion, so the motor side is
  scaled as n = s^4 identical motors in parallel (R, Ld, Lq / n; torques, J_m, tau_f x n; same
  flux linkage, speeds and voltages) and the screw lead x s; screw viscous friction x s^2.

Run ``python optimize/make_seed_scale.py`` to regenerate the two YAML files in ``optimize/``.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ChainLengths, ClosedChain
from hiab_sim.crane.loader import crane_from_dict
from hiab_sim.resources import shipped, shipped_folder
from hiab_sim.yaml_fields import read_yaml

SEED_XI = {"lift": ChainLengths(1.75, 0.544, 1.27), "tilt": ChainLengths(1.75, 0.55, 1.2)}


def _scale(values: Any, factor: float) -> Any:
    if isinstance(values, list):
        return [_scale(v, factor) for v in values]
    return float(values) * factor


def scale_crane_document(doc: dict[str, Any], s: float) -> dict[str, Any]:
    """Scale a crane YAML mapping by s (lengths s, masses s^3, inertias s^5; angles kept)."""
    out = copy.deepcopy(doc)
    out["name"] = f"{doc['name']} scaled x{s:.4f}"
    for chain in out["chains"].values():
        for key in ("cylinder_base_pivot", "L", "L1", "Lc", "Lc0", "stroke"):
            chain[key] = _scale(chain[key], s)
    tele = out["telescope"]
    tele["cylinder_frame"]["r"] = _scale(tele["cylinder_frame"]["r"], s)
    for key in ("rod_offset", "rod_length", "stroke", "joint_range"):
        tele[key] = _scale(tele[key], s)
    out["tcp"]["r"] = _scale(out["tcp"]["r"], s)
    for body in out["bodies"].values():
        body["mass"] = _scale(body["mass"], s**3)
        body["com"] = _scale(body["com"], s)
        body["inertia"] = _scale(body["inertia"], s**5)
    return out


def scale_emla_document(doc: dict[str, Any], s: float) -> dict[str, Any]:
    """Scale an EMLA YAML mapping for a crane scaled by s (see the module docstring)."""
    out = copy.deepcopy(doc)
    n = s**4

    def put(node: dict[str, Any], key: str, factor: float) -> None:
        item = node[key]
        if isinstance(item, dict):
            item["value"] = float(item["value"]) * factor
            item["source"] = f"derived: x{factor:.4g} from the XS 031 set ({item.get('source', '')})"
        else:
            node[key] = float(item) * factor

    pmsm = out["pmsm"]
    for key in ("stator_resistance", "Ld", "Lq"):
        put(pmsm, key, 1.0 / n)
    for key in ("rated_torque", "peak_torque", "rotor_inertia", "rotor_coulomb_friction"):
        put(pmsm, key, n)
    for act in out["actuators"].values():
        put(act, "screw_lead", s)
        put(act, "viscous_friction", s**2)
        for key in ("hydraulic_push_force", "hydraulic_pull_force"):
            if key in act:
                put(act, key, s**3)
    return out


def seed_scale() -> float:
    """S = 1.75 m / L of the XS 031 lift chain."""
    doc = read_yaml(shipped("crane", "xs031"))
    return 1.75 / float(doc["chains"]["lift"]["L"])


def write_seed_scale_files(folder: Path | None = None) -> tuple[Path, Path]:
    """Write the scaled crane and EMLA YAML files for ``seed_scale_spiral.yaml`` (default: next to it)."""
    folder = Path(str(shipped_folder("study"))) if folder is None else folder
    s = seed_scale()
    crane_doc = scale_crane_document(read_yaml(shipped("crane", "xs031")), s)
    crane_doc["source"] = (
        f"XS 031 (Petrovic & Mattila 2022) scaled by s = {s:.6f} by optimize/make_seed_scale.py; the seed paper's "
        "own crane data is not public. Joint ranges: those reachable by the seed's start lengths."
    )
    for name, xi in SEED_XI.items():
        chain = crane_doc["chains"][name]
        chain.update({"L": xi.L, "Lc0": xi.Lc0, "Lc": xi.Lc})
        probe = ClosedChain(
            name=name,
            parent=chain["parent"],
            cylinder_base_pivot=tuple(chain["cylinder_base_pivot"]),
            base_axis_angle=chain["base_axis_angle"],
            joint_offset=chain["joint_offset"],
            L1=chain["L1"],
            default_lengths=xi,
            stroke=chain["stroke"],
            joint_range=(-np.pi, np.pi),  # not used by reachable_joint_range
        )
        reach = mechanism.reachable_joint_range(probe, xi)
        margin = np.radians(2.0)
        chain["joint_range"] = [
            float(reach[0] + margin),
            float(min(reach[1], chain["joint_offset"] - np.radians(10.0)) - margin),
        ]
    crane_from_dict(crane_doc, origin="scaled")  # validates the result
    crane_path = folder / "xs031_seed_scale_crane.yaml"
    emla_doc = scale_emla_document(read_yaml(shipped("emla", "default")), s)
    emla_path = folder / "emla_seed_scale.yaml"
    header = f"# Generated by `python optimize/make_seed_scale.py` (s = {s:.6f}); see optimize/make_seed_scale.py.\n"
    crane_path.write_text(header + yaml.safe_dump(crane_doc, sort_keys=False))
    emla_path.write_text(header + yaml.safe_dump(emla_doc, sort_keys=False))
    return crane_path, emla_path


if __name__ == "__main__":
    for path in write_seed_scale_files():
        print(f"wrote {path}")

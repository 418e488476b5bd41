"""Soil files -> :class:`~hiab_sim.machine.dynamics.soil.SoilProperties` (a shipped name or a path).

A soil file (``hiab_sim/presets/soil_<name>.yaml``) holds the six numbers of the fundamental
earthmoving equation in SI units (angles in radians), each as ``{value, source}`` with the
provenance words of the EMLA files (``read``, ``derived``, ``estimate``), plus a ``name`` and a
whole-file ``source``::

    name: loose sand
    source: EM 1110-2-2504 (1994) Table 3-1; ...
    density_kg_m3: {value: 1762.0, source: "derived: ..."}
    friction_angle_rad: {value: 0.5061455, source: "derived: ..."}
    cohesion_Pa: {value: 0.0, source: "read: ..."}
    tool_friction_angle_rad: {value: 0.2914568, source: "derived: ..."}
    adhesion_Pa: {value: 0.0, source: "read: ..."}
    surcharge_Pa: {value: 0.0, source: "estimate: ..."}

The structure (unknown or missing keys, a word where a number belongs, a value without a source)
raises :class:`~hiab_sim.errors.ConfigError`; the ranges are checked by ``SoilProperties`` and
raise :class:`~hiab_sim.errors.InvalidInputError` naming the field (``soil.cohesion_Pa`` ...).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from hiab_sim.errors import ConfigError
from hiab_sim.machine.dynamics.soil import SoilProperties
from hiab_sim.resources import Source, locate, shipped_names
from hiab_sim.yaml_fields import mapping, read_yaml, sourced_number, text

#: Shipped soils' names (files in hiab_sim/presets/, :mod:`hiab_sim.resources` kind ``soil``).
SOILS: tuple[str, ...] = tuple(shipped_names("soil"))
#: The numbers of a soil file, in the order of SoilProperties' fields.
FIELDS = (
    "density_kg_m3",
    "friction_angle_rad",
    "cohesion_Pa",
    "tool_friction_angle_rad",
    "adhesion_Pa",
    "surcharge_Pa",
)
#: Provenance words a value's source starts with.
PROVENANCE = ("read", "derived", "estimate")


def soil_from_mapping(data: Any, where: str = "soil") -> SoilProperties:
    """Build SoilProperties from a parsed soil file; every number needs a ``{value, source}`` pair."""
    node: Mapping[str, Any] = mapping(data, where, {"name", *FIELDS, "source"})
    values: dict[str, float] = {}
    for key in FIELDS:
        if not isinstance(node[key], Mapping) or "source" not in node[key]:
            raise ConfigError(f"{where}.{key}: give it as {{value, source}}: soil data need their source")
        values[key], _ = sourced_number(node[key], f"{where}.{key}", PROVENANCE)
    name = text(node["name"], f"{where}.name")
    source = text(node["source"], f"{where}.source")
    return SoilProperties(**values, source=f"{name}: {source}")


def load_soil(source: str | Path | Source) -> SoilProperties:
    """Read a soil file (a shipped name or a path, :func:`hiab_sim.resources.locate`) into validated SoilProperties."""
    found = locate(source, "soil")
    return soil_from_mapping(read_yaml(found), where=found.label)

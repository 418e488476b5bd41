"""The soil file's keys (:func:`hiab_sim.machine.dynamics.soil_file.soil_from_mapping`), from ``SoilProperties``.

Every number is a ``{value, source}`` pair (soil data vary by an order of magnitude: no bare numbers),
its source starting with one of the soil file's provenance words.
"""

from __future__ import annotations

from dataclasses import replace

from hiab_sim.docs_site.field_specs.rows import Key, from_class, text


def soil_keys() -> list[Key]:
    """The soil file (:func:`hiab_sim.machine.dynamics.soil_file.load_soil`): six sourced numbers, a name, a source."""
    from hiab_sim.machine.dynamics.soil import SoilProperties
    from hiab_sim.machine.dynamics.soil_file import FIELDS, PROVENANCE

    sourced = "{value, source}, source starting with " + ", ".join(f"`{w}`" for w in PROVENANCE)
    rows = {k.path: k for k in from_class("", SoilProperties, skip=("source",))}
    return [
        text("name", "The soil's name (reports: `<name>: <source>`)."),
        text("source", "Where the file's numbers come from, as a whole (cited sources)."),
        *[replace(rows[key], type=sourced) for key in FIELDS],
    ]

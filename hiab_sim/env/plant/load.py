"""Read a plant YAML file (a shipped preset such as ``realistic``, or a path) into a :class:`Plant`.

The file has one mapping per effect of :data:`~hiab_sim.env.plant.config.EFFECTS`; each holds
``enabled: true|false`` and the section's fields, every number either bare or ``{value, source}``
with a source whose first word is ``read``, ``estimate``, ``derived`` or ``model``. Structure and
types raise :class:`~hiab_sim.errors.ConfigError`; ranges are checked by the dataclasses.

The drive train's stiffness is the EMLA file's (``drive_stiffness``, its one owner): a plant file
that still sets ``drive_train.axial_stiffness_N_per_m`` is refused with a one-line error saying so.
"""

from __future__ import annotations

import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from hiab_sim.emla.config import PROVENANCE_KINDS
from hiab_sim.env.plant.config import EFFECTS, CurrentLoop, DriveTrain, JointFriction, Mismatch, Plant, Sensors, Thermal
from hiab_sim.errors import ConfigError
from hiab_sim.resources import Source, locate
from hiab_sim.yaml_fields import integer, mapping, number, read_yaml, vector

_SECTIONS: dict[str, type] = {
    "drive_train": DriveTrain,
    "joint_friction": JointFriction,
    "sensors": Sensors,
    "current_loop": CurrentLoop,
    "thermal": Thermal,
    "mismatch": Mismatch,
}


def _value_and_source(raw: Any, key: str) -> tuple[Any, str]:
    """The raw value and its provenance from a bare value or a ``{value, source}`` mapping."""
    if not isinstance(raw, Mapping):
        return raw, "unspecified"
    mapping(raw, key, {"value", "source"}, {"value"})
    source = raw.get("source", "unspecified")
    if "source" in raw and (not isinstance(source, str) or source.split(":", 1)[0].strip() not in PROVENANCE_KINDS):
        raise ConfigError(f"{key}.source must be a string starting with one of {', '.join(PROVENANCE_KINDS)}")
    return raw["value"], source


#: Keys that moved out of the plant file, with where they live now.
_MOVED: dict[str, str] = {
    "drive_train.axial_stiffness_N_per_m": "the EMLA file's drive_stiffness section (hiab_sim.emla.drive_stiffness)",
    **{
        f"current_loop.{name}": "the EMLA file's drive_losses section (inverter_constant_loss, inverter_current_loss, "
        "inverter_resistance; hiab_sim.emla.losses)"
        for name in ("threshold_voltage_V", "on_resistance_ohm", "switching_loss_W_per_A", "constant_loss_W")
    },
}


def _read_section(cls: type, node: Any, where: str, provenance: list[tuple[str, str]]) -> Any:
    """One effect's section as its dataclass; appends (field, source) of every value to ``provenance``."""
    for key, home in _MOVED.items():
        section, name = key.split(".")
        if where == section and isinstance(node, Mapping) and name in node:
            raise ConfigError(f"{key}: the plant reads this from {home}; remove it from the plant file")
    hints = typing.get_type_hints(cls)
    data = mapping(node, where, set(hints), {n for n in hints if n != "seed"})
    values: dict[str, Any] = {}
    for name, kind in hints.items():
        if name not in data:
            continue
        key = f"{where}.{name}"
        if name == "enabled":
            if not isinstance(data[name], bool):
                raise ConfigError(f"{key}: expected true or false, got {data[name]!r}")
            values[name] = data[name]
            continue
        raw, source = _value_and_source(data[name], key)
        if kind is int:
            values[name] = integer(raw, key)
        elif kind is float:
            values[name] = number(raw, key)
        else:
            values[name] = vector(raw, key, 3)
        provenance.append((key, source))
    return cls(**values)


def machine_plant(source: str | Path, realistic: str | None) -> Plant:
    """``--plant`` on a machine file's result: ``realistic`` means the machine's own realistic plant.

    ``realistic``: the machine file's ``realistic_plant`` (:attr:`hiab_sim.machine.description.Machine.realistic_plant`:
    a shipped plant name or an absolute path) or None, when ``realistic`` is the shipped one (the XS 031's
    estimates). ``ideal`` and a plant file are read as :func:`load_plant` reads them.
    """
    if str(source) == "realistic" and realistic is not None:
        return load_plant(realistic)
    return load_plant(source)


def load_plant(source: str | Path | Source) -> Plant:
    """Load a plant: a shipped preset name (``realistic``), ``ideal`` (realistic, every effect off) or a YAML path."""
    if isinstance(source, str) and source == "ideal":
        return load_plant("realistic").ideal()
    found = source if isinstance(source, Source) else locate(source, "plant")
    data = mapping(read_yaml(found), found.label, set(EFFECTS))
    provenance: list[tuple[str, str]] = []
    sections = {name: _read_section(cls, data[name], name, provenance) for name, cls in _SECTIONS.items()}
    name = Path(found.label).stem if not found.shipped else found.label
    return Plant(name=name, provenance=tuple(provenance), **sections)

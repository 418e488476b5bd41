"""EMLA files: the YAML loader with provenance (the parameters' dataclasses are :mod:`hiab_sim.emla.params`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields
from pathlib import Path
from typing import Any

from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.emla.battery import BatteryParams
from hiab_sim.emla.brake import HoldingBrake
from hiab_sim.emla.drive_stiffness import DriveStiffness
from hiab_sim.emla.electrothermal import WindingResistance
from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.emla.losses import DriveLosses
from hiab_sim.emla.params import EmlaParams, PmsmParams, ScrewColumn
from hiab_sim.emla.thermal import ThermalParams
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import Source, locate
from hiab_sim.yaml_fields import mapping, read_yaml, sourced_number

#: First words allowed in a ``source`` provenance label.
PROVENANCE_KINDS: tuple[str, ...] = ("read", "estimate", "derived", "model")

__all__ = [
    "PROVENANCE_KINDS",
    "DriveStiffness",
    "EmlaParams",
    "EmlaSet",
    "PmsmParams",
    "ScrewColumn",
    "emla_set_from_mapping",
    "load_emla_set",
]


_PMSM_KEYS: tuple[str, ...] = tuple(f.name for f in fields(PmsmParams) if f.name != "label")
_ACTUATOR_REQUIRED: tuple[str, ...] = ("gear_ratio", "screw_lead", "screw_moving_mass", "viscous_friction")
_ACTUATOR_OPTIONAL: tuple[str, ...] = (
    "hydraulic_push_force",
    "hydraulic_pull_force",
    "pmsm",
    "thermal",
    "drive_losses",
    "winding_resistance",
    "holding_brake",
    "screw",
    "drive_stiffness",
)
#: Optional sections (shared at the top level; ``thermal`` and ``drive_losses`` may be overridden per actuator).
_THERMAL_KEYS: tuple[str, ...] = tuple(f.name for f in fields(ThermalParams) if f.name != "label")
_LOSS_KEYS: tuple[str, ...] = tuple(f.name for f in fields(DriveLosses) if f.name != "label")
_WINDING_KEYS: tuple[str, ...] = tuple(f.name for f in fields(WindingResistance) if f.name != "label")
_BRAKE_KEYS: tuple[str, ...] = tuple(f.name for f in fields(HoldingBrake) if f.name != "label")
_BATTERY_KEYS: tuple[str, ...] = tuple(f.name for f in fields(BatteryParams))
_SCREW_KEYS: tuple[str, ...] = tuple(f.name for f in fields(ScrewColumn) if f.name != "label")
_STIFFNESS_KEYS: tuple[str, ...] = tuple(f.name for f in fields(DriveStiffness) if f.name != "label")
#: Keys of the optional sections that may be left out (their dataclass default applies).
_SCREW_OPTIONAL: tuple[str, ...] = ("retracted_length",)


def load_emla_set(path: str | Path | Source | None = None, relative_to: Source | None = None) -> EmlaSet:
    """Load an EMLA set from YAML: a preset name (``default``, ``xs031``), a path or a :class:`Source`.

    ``None`` loads the XS 031 default preset; a relative path resolves next to ``relative_to``
    when given (see :func:`hiab_sim.resources.locate`). The file has a shared ``pmsm`` section
    and an ``actuators`` section with one section per actuator, named as the machine names them (the
    XS 031's ``lift``, ``tilt``, ``telescope`` are put in that order); an actuator may
    override motor parameters in its own ``pmsm`` mapping. Every value is a bare number or
    ``{value: ..., source: "read|estimate|derived|model: ..."}``.

    Raises:
        ConfigError: The file is missing, is not YAML, or has unknown, missing or non-numeric keys.
        InvalidInputError: A value is out of range (the message names field, value and range).

    """
    if isinstance(path, Source):
        found = path
    else:
        found = locate("default" if path is None else path, "emla", relative_to)
    return emla_set_from_mapping(read_yaml(found), where=found.label)


def emla_set_from_mapping(document: object, where: str = "<mapping>") -> EmlaSet:
    """Build an :class:`EmlaSet` from an already parsed YAML document (see :func:`load_emla_set`)."""
    root = mapping(
        document,
        f"{where}: top level",
        {
            "pmsm",
            "actuators",
            "thermal",
            "drive_losses",
            "battery",
            "winding_resistance",
            "holding_brake",
            "screw",
            "drive_stiffness",
        },
        {"pmsm", "actuators"},
    )
    shared_pmsm = mapping(root["pmsm"], f"{where}: pmsm", set(_PMSM_KEYS))
    actuators = mapping(root["actuators"], f"{where}: actuators", None)
    if not actuators:
        raise ConfigError(f"{where}: actuators: at least one actuator is needed")

    built: dict[str, EmlaParams] = {}
    for name in actuators:
        if not isinstance(name, str) or not name.isidentifier():
            raise InvalidInputError(f"{where}: actuators", name, "names must be identifiers (letters, digits, _)")
        section = f"actuators.{name}"
        node = mapping(
            actuators[name], f"{where}: {section}", {*_ACTUATOR_REQUIRED, *_ACTUATOR_OPTIONAL}, set(_ACTUATOR_REQUIRED)
        )
        override = mapping(node.get("pmsm", {}), f"{where}: {section}.pmsm", set(_PMSM_KEYS), set())
        provenance: list[tuple[str, str]] = []
        motor_values: dict[str, Any] = {}
        for key in _PMSM_KEYS:
            src_node = override[key] if key in override else shared_pmsm[key]
            src_section = f"{section}.pmsm" if key in override else "pmsm"
            value, source = sourced_number(src_node, f"{where}: {src_section}.{key}", PROVENANCE_KINDS)
            motor_values[key] = value
            provenance.append((f"pmsm.{key}", source))
        pole_pairs = motor_values["pole_pairs"]  # a count: PmsmParams rejects a non-integral value
        motor_values["pole_pairs"] = int(pole_pairs) if pole_pairs.is_integer() else pole_pairs
        motor = PmsmParams(**motor_values, label=f"{name}.pmsm" if override else "pmsm")
        values: dict[str, Any] = {}
        for key in (*_ACTUATOR_REQUIRED, "hydraulic_push_force", "hydraulic_pull_force"):
            if key in node:
                values[key], source = sourced_number(node[key], f"{where}: {section}.{key}", PROVENANCE_KINDS)
                provenance.append((key, source))
        values["thermal"] = _optional_section(
            ThermalParams, _THERMAL_KEYS, root, node, "thermal", where, name, provenance, required=True
        )
        losses = _optional_section(
            DriveLosses, _LOSS_KEYS, root, node, "drive_losses", where, name, provenance, switchable=True
        )
        if losses is not None:
            values["losses"] = losses
        values["winding"] = _optional_section(
            WindingResistance, _WINDING_KEYS, root, node, "winding_resistance", where, name, provenance, required=True
        )
        values["brake"] = _optional_section(
            HoldingBrake, _BRAKE_KEYS, root, node, "holding_brake", where, name, provenance, required=True
        )
        for section, cls, keys, optional in (
            ("screw", ScrewColumn, _SCREW_KEYS, _SCREW_OPTIONAL),
            ("drive_stiffness", DriveStiffness, _STIFFNESS_KEYS, ()),
        ):
            if section in root or section in node:
                _require_keys(root, node, section, keys, optional, where, name)
                built_section = _optional_section(cls, keys, root, node, section, where, name, provenance)
                values["screw" if section == "screw" else "stiffness"] = built_section
        built[name] = EmlaParams(name=name, motor=motor, provenance=tuple(provenance), **values)
    battery: dict[str, Any] = {}
    if "battery" in root:
        node = mapping(root["battery"], f"{where}: battery", set(_BATTERY_KEYS), set())
        battery = {key: sourced_number(node[key], f"{where}: battery.{key}", PROVENANCE_KINDS)[0] for key in node}
    emlas = EmlaSet(*built.values(), battery=BatteryParams(**battery))
    # the XS 031's three actuators keep their one order whatever the file's (a YAML dump sorts keys)
    return emlas.renamed(ACTUATOR_NAMES, where) if set(emlas.names) == set(ACTUATOR_NAMES) else emlas


def _require_keys(
    root: Mapping[str, Any],
    actuator: Mapping[str, Any],
    section: str,
    keys: tuple[str, ...],
    optional: tuple[str, ...],
    where: str,
    name: str,
) -> None:
    """Raise :class:`ConfigError` unless the shared ``section`` and the actuator's give every required key."""
    shared = mapping(root.get(section, {}), f"{where}: {section}", set(keys), set())
    override = mapping(actuator.get(section, {}), f"{where}: actuators.{name}.{section}", set(keys), set())
    missing = sorted(set(keys) - set(optional) - set(shared) - set(override))
    if missing:
        raise ConfigError(f"{where}: actuators.{name}.{section}: missing key(s) {', '.join(missing)}")


def _optional_section(
    cls: Any,
    keys: tuple[str, ...],
    root: Mapping[str, Any],
    actuator: Mapping[str, Any],
    section: str,
    where: str,
    name: str,
    provenance: list[tuple[str, str]],
    required: bool = False,
    switchable: bool = False,
) -> Any:
    """Build ``cls`` from the shared ``section`` overlaid with the actuator's own, or None if neither exists.

    With ``switchable``, ``enabled: false`` in the shared section keeps the dataclass defaults (all
    off). With ``required``, every key must be given (shared or overridden).
    """
    if section not in root and section not in actuator:
        return None
    shared = dict(mapping(root.get(section, {}), f"{where}: {section}", None))
    enabled = shared.pop("enabled", True) if switchable else True
    if not isinstance(enabled, bool):
        raise ConfigError(f"{where}: {section}.enabled must be true or false, got {enabled!r}")
    override = mapping(actuator.get(section, {}), f"{where}: actuators.{name}.{section}", set(keys), set())
    merged = {**shared, **override}
    mapping(merged, f"{where}: {section}", set(keys), set(keys) if required else set())
    if not enabled:
        return cls(label=f"{name}.{section}")
    values: dict[str, Any] = {}
    for key in merged:
        scope = f"actuators.{name}.{section}" if key in override else section
        values[key], source = sourced_number(merged[key], f"{where}: {scope}.{key}", PROVENANCE_KINDS)
        provenance.append((f"{section}.{key}", source))
    return cls(**values, label=f"{name}.{section}")

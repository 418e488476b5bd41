"""EMLA parameters: frozen dataclasses, their validation, and the YAML loader with provenance."""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

from hiab_sim.checks import check_non_negative, check_positive, check_range
from hiab_sim.crane.names import ACTUATOR_NAMES  # noqa: F401  (the XS 031 callers still import it from here)
from hiab_sim.emla.battery import BatteryParams
from hiab_sim.emla.brake import HoldingBrake
from hiab_sim.emla.drive_stiffness import DriveStiffness
from hiab_sim.emla.electrothermal import WindingResistance
from hiab_sim.emla.losses import DriveLosses
from hiab_sim.emla.thermal import ThermalParams
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import Source, locate
from hiab_sim.yaml_fields import mapping, read_yaml, sourced_number

#: First words allowed in a ``source`` provenance label.
PROVENANCE_KINDS: tuple[str, ...] = ("read", "estimate", "derived", "model")


@dataclass(frozen=True)
class PmsmParams:
    """Permanent-magnet synchronous motor in the dq frame (eqs. ``dq0voltage``, ``torque_torque``).

    Attributes:
        pole_pairs: Number of pole pairs p [-], a positive integer.
        flux_linkage: Permanent-magnet flux linkage Phi_PM [Wb].
        stator_resistance: Stator resistance per phase R_s [ohm].
        Ld: d-axis inductance [H].
        Lq: q-axis inductance [H].
        rated_speed_rpm: Rated (maximum continuous) motor speed [rev/min].
        rated_torque: Rated motor torque [N m] (reported, not a limit of the envelope).
        peak_torque: Peak motor torque tau_peak [N m], a limit of the envelope.
        rotor_inertia: Rotor inertia J_m [kg m^2] (with the gearbox input side).
        rotor_coulomb_friction: Rotor Coulomb friction torque tau_f [N m].
        max_line_voltage_rms: Largest line-to-line rms voltage the inverter applies [V].
        friction_smoothing_speed: omega_eps [rad/s] of the regularised Coulomb friction
            tau_f tanh(omega_m / omega_eps); a model choice, not a motor datum.
        label: Prefix used in error messages.

    """

    pole_pairs: int
    flux_linkage: float
    stator_resistance: float
    Ld: float
    Lq: float
    rated_speed_rpm: float
    rated_torque: float
    peak_torque: float
    rotor_inertia: float
    rotor_coulomb_friction: float
    max_line_voltage_rms: float
    friction_smoothing_speed: float
    label: str = "pmsm"

    def __post_init__(self) -> None:
        pp = self.pole_pairs
        if isinstance(pp, bool) or not isinstance(pp, int) or pp <= 0:
            raise InvalidInputError(f"{self.label}.pole_pairs", pp, "must be a positive integer")
        check_positive(f"{self.label}.flux_linkage", self.flux_linkage, "Wb")
        check_non_negative(f"{self.label}.stator_resistance", self.stator_resistance, "ohm")
        check_positive(f"{self.label}.Ld", self.Ld, "H")
        check_positive(f"{self.label}.Lq", self.Lq, "H")
        check_positive(f"{self.label}.rated_speed_rpm", self.rated_speed_rpm, "rev/min")
        check_positive(f"{self.label}.rated_torque", self.rated_torque, "N m")
        check_positive(f"{self.label}.peak_torque", self.peak_torque, "N m")
        check_non_negative(f"{self.label}.rotor_inertia", self.rotor_inertia, "kg m^2")
        check_non_negative(f"{self.label}.rotor_coulomb_friction", self.rotor_coulomb_friction, "N m")
        if self.rotor_coulomb_friction >= self.peak_torque:
            raise InvalidInputError(
                f"{self.label}.rotor_coulomb_friction",
                self.rotor_coulomb_friction,
                f"must be < peak_torque = {self.peak_torque:g} N m",
                "N m",
            )
        check_positive(f"{self.label}.max_line_voltage_rms", self.max_line_voltage_rms, "V")
        check_positive(f"{self.label}.friction_smoothing_speed", self.friction_smoothing_speed, "rad/s")

    @property
    def rated_speed(self) -> float:
        """Rated motor speed [rad/s]."""
        return self.rated_speed_rpm * 2.0 * math.pi / 60.0

    @property
    def torque_constant(self) -> float:
        """K_t = 3/2 p Phi_PM [N m/A]: torque per q-axis ampere with i_d = 0 (eq. ``dq0voltage``)."""
        return 1.5 * self.pole_pairs * self.flux_linkage


@dataclass(frozen=True)
class ScrewColumn:
    """The screw of an EMLA as a column under its push force (buckling, :mod:`hiab_sim.structure.buckling`).

    Attributes:
        root_diameter: Thread root (minor) diameter d_r of the screw shaft [m]; the section
            A = pi d_r^2 / 4, I = pi d_r^4 / 64 of the ball-screw catalogues' buckling formula.
        elastic_modulus: Young's modulus E of the screw steel [Pa].
        yield_strength: Compressive yield strength sigma_y of the screw core [Pa] (Johnson parabola).
        end_fixity_factor: The catalogues' mounting factor N of P = N pi^2 E I / l^2 [-]: 1 pinned-
            pinned, 2 fixed-supported, 4 fixed-fixed, 0.25 fixed-free (effective length l / sqrt(N)).
        retracted_length: Column length at zero stroke [m] of an actuator that is not in a closed
            chain (a direct actuator); None for a chain's actuator, whose column is its pin-to-pin
            length x0 + x.
        label: Prefix used in error messages.

    """

    root_diameter: float
    elastic_modulus: float
    yield_strength: float
    end_fixity_factor: float
    retracted_length: float | None = None
    label: str = "screw"

    def __post_init__(self) -> None:
        check_positive(f"{self.label}.root_diameter", self.root_diameter, "m")
        check_positive(f"{self.label}.elastic_modulus", self.elastic_modulus, "Pa")
        check_positive(f"{self.label}.yield_strength", self.yield_strength, "Pa")
        if not (math.isfinite(self.yield_strength) and self.yield_strength < self.elastic_modulus):
            raise InvalidInputError(
                f"{self.label}.yield_strength", self.yield_strength, "must be < elastic_modulus", "Pa"
            )
        check_range(f"{self.label}.end_fixity_factor", self.end_fixity_factor, 0.0, 4.0, low_open=True)
        if self.retracted_length is not None:
            check_positive(f"{self.label}.retracted_length", self.retracted_length, "m")


@dataclass(frozen=True)
class EmlaParams:
    """One electromechanical linear actuator: PMSM, gearbox, screw (eqs. ``torque_torque``, ``torque_force``).

    Attributes:
        name: Actuator name (``lift``, ``tilt`` or ``telescope`` for the XS 031), used in messages.
        motor: The PMSM.
        gear_ratio: Gearbox ratio G [-] (motor turns per screw turn), > 1 (a reduction).
        screw_lead: Screw lead rho [m per screw revolution], > 0.
        screw_moving_mass: Screw moving mass M_sm [kg], >= 0.
        viscous_friction: Screw viscous friction b_f [N s/m], >= 0.
        hydraulic_push_force: Push force of the hydraulic cylinder this EMLA replaces [N], or None.
        hydraulic_pull_force: Pull force of that cylinder [N], or None.
        losses: Optional drive losses (:mod:`hiab_sim.emla.losses`); the default is all off.
        thermal: Continuous torque and winding thermal model (:mod:`hiab_sim.emla.thermal`), or None.
        winding: Temperature dependence of R_s (:mod:`hiab_sim.emla.electrothermal`), or None
            (R_s constant, the seed paper's model).
        brake: The holding brake on the motor shaft (:mod:`hiab_sim.emla.brake`), or None.
        screw: The screw as a column (buckling), or None when the file gives no ``screw`` section.
        stiffness: Drive-train stiffness data (:mod:`hiab_sim.emla.drive_stiffness`), or None without it.
        provenance: (parameter key, source label) pairs, e.g.
            ``("pmsm.peak_torque", "estimate: 3 x rated torque ...")``.

    """

    name: str
    motor: PmsmParams
    gear_ratio: float
    screw_lead: float
    screw_moving_mass: float
    viscous_friction: float
    hydraulic_push_force: float | None = None
    hydraulic_pull_force: float | None = None
    losses: DriveLosses = field(default_factory=DriveLosses)
    thermal: ThermalParams | None = None
    winding: WindingResistance | None = None
    brake: HoldingBrake | None = None
    provenance: tuple[tuple[str, str], ...] = ()
    screw: ScrewColumn | None = None
    stiffness: DriveStiffness | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.gear_ratio) and self.gear_ratio > 1.0):
            raise InvalidInputError(f"{self.name}.gear_ratio", self.gear_ratio, "must be finite and > 1 (a reduction)")
        check_positive(f"{self.name}.screw_lead", self.screw_lead, "m")
        check_non_negative(f"{self.name}.screw_moving_mass", self.screw_moving_mass, "kg")
        check_non_negative(f"{self.name}.viscous_friction", self.viscous_friction, "N s/m")
        for key in ("hydraulic_push_force", "hydraulic_pull_force"):
            value = getattr(self, key)
            if value is not None:
                check_positive(f"{self.name}.{key}", value, "N")

    @property
    def transmission_ratio(self) -> float:
        """Transmission ratio k = 2 pi G / rho [rad/m]: motor angle per rod metre (eq. ``torque_force``)."""
        return 2.0 * math.pi * self.gear_ratio / self.screw_lead

    def source_of(self, key: str) -> str:
        """Return the provenance label of a parameter key such as ``"gear_ratio"`` or ``"pmsm.Ld"``."""
        return dict(self.provenance).get(key, "unspecified")


@dataclass(frozen=True, init=False)
class EmlaSet:
    """The EMLAs of a machine, one per actuator in the machine's actuator order, and their DC bus.

    Iterating gives the :class:`EmlaParams` in order; ``emlas[name]`` and ``emlas.<name>`` give one
    actuator's by its name (each EMLA's ``name`` is its actuator's). Build it as
    ``EmlaSet(p1, p2, ..., battery=...)`` or ``EmlaSet(**{name: params})`` (keywords in the
    machine's actuator order).
    """

    params: tuple[EmlaParams, ...]
    battery: BatteryParams

    def __init__(
        self, *params: EmlaParams, battery: BatteryParams | None = None, **named: EmlaParams | BatteryParams
    ) -> None:
        values = list(params)
        given = named.pop("params", None)  # dataclasses.replace passes the fields by name
        if isinstance(given, tuple):
            values += list(given)
        if values and isinstance(values[-1], BatteryParams) and battery is None:
            battery = values.pop()  # positional battery last, as the dataclass constructor took it
        for name, value in named.items():
            if not isinstance(value, EmlaParams):
                raise InvalidInputError(f"actuators.{name}", type(value).__name__, "must be an EMLA's parameters")
            values.append(value if value.name == name else replace(value, name=name))
        if not values:
            raise InvalidInputError("actuators", "none", "an EMLA set needs at least one actuator")
        names = [p.name for p in values]
        if len(set(names)) != len(names):
            raise InvalidInputError("actuators", ", ".join(names), "names must be unique")
        object.__setattr__(self, "params", tuple(values))
        object.__setattr__(self, "battery", battery if battery is not None else BatteryParams())
        if self.battery.inverter_efficiency < 1.0 and any(p.losses.inverter_on for p in self.params):
            raise InvalidInputError(
                "battery.inverter_efficiency",
                self.battery.inverter_efficiency,
                "must be 1 when drive_losses models the inverter (it would be counted twice)",
            )

    @property
    def names(self) -> tuple[str, ...]:
        """The actuators' names, in order."""
        return tuple(p.name for p in self.params)

    def __len__(self) -> int:
        return len(self.params)

    def __iter__(self) -> Iterator[EmlaParams]:
        return iter(self.params)

    def __getitem__(self, name: str) -> EmlaParams:
        """Return the actuator called ``name`` (one of :attr:`names`)."""
        for p in self.params:
            if p.name == name:
                return p
        raise InvalidInputError("actuator", name, f"must be one of {', '.join(self.names)}")

    def __getattr__(self, name: str) -> EmlaParams:
        if name.startswith("_") or name in ("params", "battery"):
            raise AttributeError(name)
        for p in self.__dict__.get("params", ()):
            if p.name == name:
                return p
        raise AttributeError(f"EmlaSet has no actuator {name!r}")

    def as_tuple(self) -> tuple[EmlaParams, ...]:
        """Return the EMLAs in actuator order."""
        return self.params

    def replaced(self, **named: EmlaParams) -> EmlaSet:
        """This set with the named actuators' parameters replaced (the others and the battery kept)."""
        unknown = set(named) - set(self.names)
        if unknown:
            raise InvalidInputError("actuator", ", ".join(sorted(unknown)), f"must be one of {', '.join(self.names)}")
        return EmlaSet(*(named.get(p.name, p) for p in self.params), battery=self.battery)

    def with_battery(self, battery: BatteryParams) -> EmlaSet:
        """This set on another DC bus and battery."""
        return EmlaSet(*self.params, battery=battery)

    def renamed(self, names: Sequence[str], where: str = "emla") -> EmlaSet:
        """This set checked against a machine's actuator names (same names, put in the machine's order)."""
        if set(names) != set(self.names) or len(names) != len(self.names):
            raise InvalidInputError(
                f"{where}: actuators", ", ".join(self.names), f"must be the machine's actuators: {', '.join(names)}"
            )
        return EmlaSet(*(self[n] for n in names), battery=self.battery)


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
    and an ``actuators`` section with ``lift``, ``tilt`` and ``telescope``; an actuator may
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
    return EmlaSet(*built.values(), battery=BatteryParams(**battery))


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

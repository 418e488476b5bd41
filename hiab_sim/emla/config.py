"""EMLA parameters: frozen dataclasses, their validation, and the YAML loader with provenance."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.errors import InvalidInputError
from hiab_sim.resources import Source, locate
from hiab_sim.yaml_fields import mapping, read_yaml, sourced_number

#: First words allowed in a ``source`` provenance label.
PROVENANCE_KINDS: tuple[str, ...] = ("read", "estimate", "derived", "model")


def _positive(field: str, value: float, unit: str = "") -> None:
    if not (math.isfinite(value) and value > 0):
        raise InvalidInputError(field, value, "must be finite and > 0", unit)


def _non_negative(field: str, value: float, unit: str = "") -> None:
    if not (math.isfinite(value) and value >= 0):
        raise InvalidInputError(field, value, "must be finite and >= 0", unit)


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
        _positive(f"{self.label}.flux_linkage", self.flux_linkage, "Wb")
        _non_negative(f"{self.label}.stator_resistance", self.stator_resistance, "ohm")
        _positive(f"{self.label}.Ld", self.Ld, "H")
        _positive(f"{self.label}.Lq", self.Lq, "H")
        _positive(f"{self.label}.rated_speed_rpm", self.rated_speed_rpm, "rev/min")
        _positive(f"{self.label}.rated_torque", self.rated_torque, "N m")
        _positive(f"{self.label}.peak_torque", self.peak_torque, "N m")
        _non_negative(f"{self.label}.rotor_inertia", self.rotor_inertia, "kg m^2")
        _non_negative(f"{self.label}.rotor_coulomb_friction", self.rotor_coulomb_friction, "N m")
        if self.rotor_coulomb_friction >= self.peak_torque:
            raise InvalidInputError(
                f"{self.label}.rotor_coulomb_friction",
                self.rotor_coulomb_friction,
                f"must be < peak_torque = {self.peak_torque:g} N m",
                "N m",
            )
        _positive(f"{self.label}.max_line_voltage_rms", self.max_line_voltage_rms, "V")
        _positive(f"{self.label}.friction_smoothing_speed", self.friction_smoothing_speed, "rad/s")

    @property
    def rated_speed(self) -> float:
        """Rated motor speed [rad/s]."""
        return self.rated_speed_rpm * 2.0 * math.pi / 60.0

    @property
    def torque_constant(self) -> float:
        """K_t = 3/2 p Phi_PM [N m/A]: torque per q-axis ampere with i_d = 0 (eq. ``dq0voltage``)."""
        return 1.5 * self.pole_pairs * self.flux_linkage


@dataclass(frozen=True)
class EmlaParams:
    """One electromechanical linear actuator: PMSM, gearbox, screw (eqs. ``torque_torque``, ``torque_force``).

    Attributes:
        name: Actuator name (``lift``, ``tilt`` or ``telescope`` for the XS 031), used in messages.
        motor: The PMSM.
        gear_ratio: Gearbox ratio G [-] (motor turns per screw turn), > 0.
        screw_lead: Screw lead rho [m per screw revolution], > 0.
        screw_moving_mass: Screw moving mass M_sm [kg], >= 0.
        viscous_friction: Screw viscous friction b_f [N s/m], >= 0.
        hydraulic_push_force: Push force of the hydraulic cylinder this EMLA replaces [N], or None.
        hydraulic_pull_force: Pull force of that cylinder [N], or None.
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
    provenance: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        _positive(f"{self.name}.gear_ratio", self.gear_ratio)
        _positive(f"{self.name}.screw_lead", self.screw_lead, "m")
        _non_negative(f"{self.name}.screw_moving_mass", self.screw_moving_mass, "kg")
        _non_negative(f"{self.name}.viscous_friction", self.viscous_friction, "N s/m")
        for key in ("hydraulic_push_force", "hydraulic_pull_force"):
            value = getattr(self, key)
            if value is not None:
                _positive(f"{self.name}.{key}", value, "N")

    @property
    def transmission_ratio(self) -> float:
        """Transmission ratio k = 2 pi G / rho [rad/m]: motor angle per rod metre (eq. ``torque_force``)."""
        return 2.0 * math.pi * self.gear_ratio / self.screw_lead

    def source_of(self, key: str) -> str:
        """Return the provenance label of a parameter key such as ``"gear_ratio"`` or ``"pmsm.Ld"``."""
        return dict(self.provenance).get(key, "unspecified")


@dataclass(frozen=True)
class EmlaSet:
    """The three EMLAs of an XS 031 crane; iterate for ``lift``, ``tilt``, ``telescope`` in that order."""

    lift: EmlaParams
    tilt: EmlaParams
    telescope: EmlaParams

    def __iter__(self) -> Iterator[EmlaParams]:
        return iter((self.lift, self.tilt, self.telescope))

    def __getitem__(self, name: str) -> EmlaParams:
        """Return the actuator called ``name`` (one of :data:`ACTUATOR_NAMES`)."""
        if name not in ACTUATOR_NAMES:
            raise InvalidInputError("actuator", name, f"must be one of {', '.join(ACTUATOR_NAMES)}")
        params: EmlaParams = getattr(self, name)
        return params

    def as_tuple(self) -> tuple[EmlaParams, EmlaParams, EmlaParams]:
        """Return ``(lift, tilt, telescope)``."""
        return (self.lift, self.tilt, self.telescope)


_PMSM_KEYS: tuple[str, ...] = tuple(f.name for f in fields(PmsmParams) if f.name != "label")
_ACTUATOR_REQUIRED: tuple[str, ...] = ("gear_ratio", "screw_lead", "screw_moving_mass", "viscous_friction")
_ACTUATOR_OPTIONAL: tuple[str, ...] = ("hydraulic_push_force", "hydraulic_pull_force", "pmsm")


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
    root = mapping(document, f"{where}: top level", {"pmsm", "actuators"})
    shared_pmsm = mapping(root["pmsm"], f"{where}: pmsm", set(_PMSM_KEYS))
    actuators = mapping(root["actuators"], f"{where}: actuators", set(ACTUATOR_NAMES))

    built: dict[str, EmlaParams] = {}
    for name in ACTUATOR_NAMES:
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
        built[name] = EmlaParams(name=name, motor=motor, provenance=tuple(provenance), **values)
    return EmlaSet(**built)

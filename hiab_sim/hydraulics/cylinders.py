"""The hydraulic cylinders the EMLAs replace: bore, rod, areas, valves, supply pressure and friction.

One :class:`HydraulicSystem` for every machine: its cylinders in the machine's actuator order, named
by the file (a machine file's ``hydraulic`` section, a crane file's ``hydraulic_cylinders``, whose keys
are the crane's actuator names); :func:`cylinder_from_mapping` reads one cylinder for both formats.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from hiab_sim.checks import check_non_negative, check_positive
from hiab_sim.errors import InvalidInputError
from hiab_sim.yaml_fields import mapping, number


@dataclass(frozen=True)
class CounterbalanceValve:
    """A pilot-assisted counterbalance (over-centre) valve in the outlet of one chamber of a cylinder.

    It opens when p_chamber + R p_pilot >= p_set, the pilot taken from the other chamber; flow into the
    chamber passes its check valve (cracking pressure ``check_pressure``).

    Attributes:
        side: ``piston`` or ``rod``, the chamber the valve holds (the load-holding one).
        pilot_ratio: R [-] > 0.
        setting_pressure: p_set [Pa] > 0.
        check_pressure: Cracking pressure of the free-flow check [Pa] >= 0.
        label: Prefix of error messages.

    """

    side: str
    pilot_ratio: float
    setting_pressure: float
    check_pressure: float = 0.0
    label: str = "counterbalance"

    def __post_init__(self) -> None:
        if self.side not in ("piston", "rod"):
            raise InvalidInputError(f"{self.label}.side", self.side, "must be one of piston, rod")
        check_positive(f"{self.label}.pilot_ratio", self.pilot_ratio)
        check_positive(f"{self.label}.setting_pressure", self.setting_pressure, "Pa")
        check_non_negative(f"{self.label}.check_pressure", self.check_pressure, "Pa")


@dataclass(frozen=True)
class Cylinder:
    """A double-acting single-rod cylinder.

    Attributes:
        name: Actuator name.
        bore: Piston diameter D [m] > 0.
        rod: Rod diameter d [m], 0 < d < D.
        stroke: Stroke [m] > 0 (reported, not a limit here).
        pin_to_pin_at_zero: Pin-to-pin length [m] > 0 at zero joint angle, if the crane file gives it
            (documentation of the source's cylinder; the EMLA chains' own lengths are the model's).
        counterbalance: Its counterbalance valve, or None.
        label: Prefix of error messages, the cylinder's place in its file (default
            ``hydraulic_cylinders.<name>``, the crane file's).

    """

    name: str
    bore: float
    rod: float
    stroke: float
    pin_to_pin_at_zero: float | None = None
    counterbalance: CounterbalanceValve | None = None
    label: str = field(default="", compare=False, repr=False)

    def __post_init__(self) -> None:
        if not self.label:
            object.__setattr__(self, "label", f"hydraulic_cylinders.{self.name}")
        check_positive(f"{self.label}.bore", self.bore, "m")
        check_positive(f"{self.label}.rod", self.rod, "m")
        if self.rod >= self.bore:
            raise InvalidInputError(f"{self.label}.rod", self.rod, f"must be < bore = {self.bore:g} m", "m")
        check_positive(f"{self.label}.stroke", self.stroke, "m")
        if self.pin_to_pin_at_zero is not None:
            check_positive(f"{self.label}.pin_to_pin_at_zero", self.pin_to_pin_at_zero, "m")

    @property
    def piston_area(self) -> float:
        """A_p = pi D^2 / 4 [m^2], the piston (cap) side: pushes while extending."""
        return 0.25 * math.pi * self.bore**2

    @property
    def annulus_area(self) -> float:
        """A_r = pi (D^2 - d^2) / 4 [m^2], the rod side: pulls while retracting."""
        return 0.25 * math.pi * (self.bore**2 - self.rod**2)


@dataclass(frozen=True)
class HydraulicSystem:
    """The hydraulic cylinders the EMLAs replace (the baseline), supply pressure [Pa], friction.

    Attributes:
        cylinders: The cylinders, in the machine's actuator order (the hydraulic baseline's columns).
        supply_pressure: p_s [Pa] > 0, the system (relief) pressure.
        coulomb_friction: F_c [N] >= 0 per cylinder, seal friction opposing the rod velocity.
        viscous_friction: b [N s/m] >= 0 per cylinder.
        label: Prefix of error messages, the section of the file (``hydraulic`` in a machine file).

    """

    cylinders: tuple[Cylinder, ...]
    supply_pressure: float
    coulomb_friction: float = 0.0
    viscous_friction: float = 0.0
    label: str = field(default="hydraulic", compare=False, repr=False)

    def __post_init__(self) -> None:
        check_positive(f"{self.label}.supply_pressure", self.supply_pressure, "Pa")
        check_non_negative(f"{self.label}.friction.coulomb", self.coulomb_friction, "N")
        check_non_negative(f"{self.label}.friction.viscous", self.viscous_friction, "N s/m")
        names = [c.name for c in self.cylinders]
        if len(set(names)) != len(names):
            raise InvalidInputError(f"{self.label}.cylinders", str(names), "names must be unique")

    def __iter__(self) -> Iterator[Cylinder]:
        """The cylinders in order (the hydraulic baseline's actuator order)."""
        return iter(self.cylinders)

    def find(self, name: str) -> Cylinder | None:
        """The cylinder of this name, or None."""
        return next((c for c in self.cylinders if c.name == name), None)

    def cylinder(self, name: str) -> Cylinder:
        """The cylinder of this name."""
        found = self.find(name)
        if found is None:
            raise InvalidInputError(
                f"{self.label}.cylinders", name, f"no such cylinder; have {[c.name for c in self.cylinders]}"
            )
        return found


def cylinder_from_mapping(node: Any, where: str, name: str, optional: frozenset[str] = frozenset()) -> Cylinder:
    """One cylinder from its mapping at ``where``: ``bore``, ``rod``, ``stroke`` [m] and the ``optional`` keys.

    Optional keys a file format may allow: ``pin_to_pin_at_zero`` [m] and ``counterbalance: {side,
    pilot_ratio, setting_pressure [Pa], check_pressure [Pa]}``.
    """
    keys = {"bore", "rod", "stroke"}
    data = mapping(node, where, keys | set(optional), keys)
    pin = data.get("pin_to_pin_at_zero")
    valve = None
    if "counterbalance" in data:
        cb_where = f"{where}.counterbalance"
        cb_keys = {"side", "pilot_ratio", "setting_pressure"}
        cb = mapping(data["counterbalance"], cb_where, cb_keys | {"check_pressure"}, cb_keys)
        valve = CounterbalanceValve(
            side=cb["side"],
            pilot_ratio=number(cb["pilot_ratio"], f"{cb_where}.pilot_ratio"),
            setting_pressure=number(cb["setting_pressure"], f"{cb_where}.setting_pressure"),
            check_pressure=number(cb.get("check_pressure", 0.0), f"{cb_where}.check_pressure"),
            label=cb_where,
        )
    bore, rod, stroke = (number(data[k], f"{where}.{k}") for k in ("bore", "rod", "stroke"))
    return Cylinder(
        name,
        bore,
        rod,
        stroke,
        pin_to_pin_at_zero=None if pin is None else number(pin, f"{where}.pin_to_pin_at_zero"),
        counterbalance=valve,
        label=where,
    )


def hydraulic_cylinders_from_mapping(
    data: Any, names: tuple[str, ...], where: str = "hydraulic_cylinders"
) -> HydraulicSystem:
    """A crane file's ``hydraulic_cylinders`` section: one cylinder per actuator, keyed by its name.

    Keys: each of ``names`` (the crane's actuators, in order; each :func:`cylinder_from_mapping` with
    ``pin_to_pin_at_zero`` and ``counterbalance``), ``supply_pressure`` [Pa], optional
    ``friction: {coulomb [N], viscous [N s/m]}``.
    """
    required = {*names, "supply_pressure"}
    top = mapping(data, where, required | {"friction"}, required)
    optional = frozenset({"pin_to_pin_at_zero", "counterbalance"})
    cylinders = tuple(cylinder_from_mapping(top[name], f"{where}.{name}", name, optional) for name in names)
    return system_from_mapping(top, where, cylinders)


def system_from_mapping(top: Mapping[str, Any], where: str, cylinders: tuple[Cylinder, ...]) -> HydraulicSystem:
    """The :class:`HydraulicSystem` of a section at ``where`` (its keys checked by the caller) and its cylinders.

    Reads ``supply_pressure`` [Pa] and the optional ``friction: {coulomb [N], viscous [N s/m]}`` (0 when absent).
    """
    friction = mapping(top.get("friction", {}), f"{where}.friction", {"coulomb", "viscous"}, set())
    return HydraulicSystem(
        cylinders,
        supply_pressure=number(top["supply_pressure"], f"{where}.supply_pressure"),
        coulomb_friction=number(friction.get("coulomb", 0.0), f"{where}.friction.coulomb"),
        viscous_friction=number(friction.get("viscous", 0.0), f"{where}.friction.viscous"),
        label=where,
    )

"""The crane's original hydraulic cylinders: bore, rod, areas, supply pressure and friction (crane YAML)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from hiab_sim.checks import check_non_negative, check_positive
from hiab_sim.errors import InvalidInputError
from hiab_sim.yaml_fields import mapping, number

#: Cylinder names, in the order of the crane's actuators.
CYLINDER_NAMES: tuple[str, ...] = ("lift", "tilt", "telescope")


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

    """

    name: str
    bore: float
    rod: float
    stroke: float
    pin_to_pin_at_zero: float | None = None
    counterbalance: CounterbalanceValve | None = None

    def __post_init__(self) -> None:
        check_positive(f"hydraulic_cylinders.{self.name}.bore", self.bore, "m")
        check_positive(f"hydraulic_cylinders.{self.name}.rod", self.rod, "m")
        if self.rod >= self.bore:
            raise InvalidInputError(
                f"hydraulic_cylinders.{self.name}.rod", self.rod, f"must be < bore = {self.bore:g} m", "m"
            )
        check_positive(f"hydraulic_cylinders.{self.name}.stroke", self.stroke, "m")
        if self.pin_to_pin_at_zero is not None:
            check_positive(f"hydraulic_cylinders.{self.name}.pin_to_pin_at_zero", self.pin_to_pin_at_zero, "m")

    @property
    def piston_area(self) -> float:
        """A_p = pi D^2 / 4 [m^2], the piston (cap) side: pushes while extending."""
        return 0.25 * math.pi * self.bore**2

    @property
    def annulus_area(self) -> float:
        """A_r = pi (D^2 - d^2) / 4 [m^2], the rod side: pulls while retracting."""
        return 0.25 * math.pi * (self.bore**2 - self.rod**2)


@dataclass(frozen=True)
class HydraulicCylinders:
    """The three cylinders, the supply pressure and the per-cylinder friction of the source simulation.

    Attributes:
        lift: Lift cylinder.
        tilt: Tilt cylinder.
        telescope: Telescope cylinder.
        supply_pressure: p_s [Pa] > 0, the system (relief) pressure.
        coulomb_friction: F_c [N] >= 0, seal friction opposing the rod velocity.
        viscous_friction: b [N s/m] >= 0.

    """

    lift: Cylinder
    tilt: Cylinder
    telescope: Cylinder
    supply_pressure: float
    coulomb_friction: float = 0.0
    viscous_friction: float = 0.0

    def __post_init__(self) -> None:
        check_positive("hydraulic_cylinders.supply_pressure", self.supply_pressure, "Pa")
        check_non_negative("hydraulic_cylinders.friction.coulomb", self.coulomb_friction, "N")
        check_non_negative("hydraulic_cylinders.friction.viscous", self.viscous_friction, "N s/m")

    def __iter__(self) -> Iterator[Cylinder]:
        return iter((self.lift, self.tilt, self.telescope))


def hydraulic_cylinders_from_mapping(data: Any, where: str = "hydraulic_cylinders") -> HydraulicCylinders:
    """Build :class:`HydraulicCylinders` from the crane YAML's ``hydraulic_cylinders`` mapping.

    Keys: ``lift``, ``tilt``, ``telescope`` (each ``bore``, ``rod``, ``stroke`` [m], optional
    ``pin_to_pin_at_zero`` and ``counterbalance: {side, pilot_ratio, setting_pressure [Pa],
    check_pressure [Pa]}``), ``supply_pressure`` [Pa], optional ``friction: {coulomb, viscous}``.
    """
    required = {"lift", "tilt", "telescope", "supply_pressure"}
    top = mapping(data, where, required | {"friction"}, required)
    cylinders = {}
    for name in CYLINDER_NAMES:
        keys = {"bore", "rod", "stroke"}
        node = mapping(top[name], f"{where}.{name}", keys | {"pin_to_pin_at_zero", "counterbalance"}, keys)
        pin = node.get("pin_to_pin_at_zero")
        valve = None
        if "counterbalance" in node:
            cb_where = f"{where}.{name}.counterbalance"
            cb_keys = {"side", "pilot_ratio", "setting_pressure"}
            cb = mapping(node["counterbalance"], cb_where, cb_keys | {"check_pressure"}, cb_keys)
            valve = CounterbalanceValve(
                side=cb["side"],
                pilot_ratio=number(cb["pilot_ratio"], f"{cb_where}.pilot_ratio"),
                setting_pressure=number(cb["setting_pressure"], f"{cb_where}.setting_pressure"),
                check_pressure=number(cb.get("check_pressure", 0.0), f"{cb_where}.check_pressure"),
                label=cb_where,
            )
        bore, rod, stroke = (number(node[k], f"{where}.{name}.{k}") for k in ("bore", "rod", "stroke"))
        cylinders[name] = Cylinder(
            name,
            bore,
            rod,
            stroke,
            pin_to_pin_at_zero=None if pin is None else number(pin, f"{where}.{name}.pin_to_pin_at_zero"),
            counterbalance=valve,
        )
    friction = mapping(top.get("friction", {}), f"{where}.friction", {"coulomb", "viscous"}, set())
    return HydraulicCylinders(
        **cylinders,
        supply_pressure=number(top["supply_pressure"], f"{where}.supply_pressure"),
        coulomb_friction=number(friction.get("coulomb", 0.0), f"{where}.friction.coulomb"),
        viscous_friction=number(friction.get("viscous", 0.0), f"{where}.friction.viscous"),
    )

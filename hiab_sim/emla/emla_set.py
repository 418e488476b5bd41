"""An EMLA set: the EMLAs of a machine, one per actuator named by its file, and their DC bus (battery).

The set is built by :func:`hiab_sim.emla.config.load_emla_set` from an EMLA file; a study puts its
actuators in the machine's actuator order (:meth:`EmlaSet.renamed`).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from typing import Any

from hiab_sim.emla.battery import BatteryParams
from hiab_sim.emla.params import EmlaParams
from hiab_sim.errors import InvalidInputError


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

    def __init__(self, *params: Any, battery: BatteryParams | None = None, **named: Any) -> None:
        values: list[Any] = list(params)
        given = named.pop("params", None)  # dataclasses.replace passes the fields by name
        if isinstance(given, tuple):
            values += list(given)
        if values and isinstance(values[-1], BatteryParams) and battery is None:
            last: BatteryParams = values.pop()  # positional battery last, as the dataclass constructor took it
            battery = last
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
        """The set with the named actuators' parameters replaced (the others and the battery kept)."""
        unknown = set(named) - set(self.names)
        if unknown:
            raise InvalidInputError("actuator", ", ".join(sorted(unknown)), f"must be one of {', '.join(self.names)}")
        return EmlaSet(*(named.get(p.name, p) for p in self.params), battery=self.battery)

    def with_battery(self, battery: BatteryParams) -> EmlaSet:
        """The set on another DC bus and battery."""
        return EmlaSet(*self.params, battery=battery)

    def renamed(self, names: Sequence[str], where: str = "emla") -> EmlaSet:
        """The set checked against a machine's actuator names (same names, put in the machine's order)."""
        if set(names) != set(self.names) or len(names) != len(self.names):
            raise InvalidInputError(
                f"{where}: actuators", ", ".join(self.names), f"must be the machine's actuators: {', '.join(names)}"
            )
        return EmlaSet(*(self[n] for n in names), battery=self.battery)

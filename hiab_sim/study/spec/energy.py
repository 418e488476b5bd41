"""The study's energy settings: objective, thermal duty and transmission catalogue.

Three optional top-level keys of a study file, each validated here into a frozen dataclass:

* ``objective: <name>`` (default ``costf2``, the seed's eq. ``costf2``; ``battery_energy``): a name
  registered in :data:`hiab_sim.study.nlp.objectives.OBJECTIVES`, the one objective registry.
* ``duty: {cycles_per_hour: n}``, ``duty: {rest_time: T_rest}`` [s] or ``duty: {rest_ratio: r}``:
  the cycle (the study's trajectory, duration T) repeats with a rest of T_rest at zero torque, n
  times an hour (T_rest = 3600/n - T) or with a rest of T_rest = r T. Each task of a mix gets its
  duty from its own duration T, so ``rest_ratio`` gives every task the same share of rest (r = 0.2:
  a 50-minute working hour, 60/50 - 1) where one ``rest_time`` cannot. With a duty and an EMLA set
  that has thermal data, the NLP holds the motors' thermal limits
  (:mod:`hiab_sim.study.constraints.thermal_rows`). ``hold: brake | motor`` says what carries the machine
  during the rest (:mod:`hiab_sim.emla.hold`); with a duty, the energy and the thermal rows use R_s
  at the winding temperature of EMLAs with ``winding_resistance`` data
  (:mod:`hiab_sim.emla.duty_energy`).
* ``transmission: {<actuator>: [{gear_ratio: G, screw_lead: rho}, ...], ...}``: a catalogue of
  discrete (G, rho) options per actuator, keyed by the study's actuator names (a crane file's lift,
  tilt, telescope; a machine file's chains); actuators not listed keep the EMLA file's. The
  co-design (:mod:`hiab_sim.study.analysis.codesign`) optimises the mounting for every combination.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from hiab_sim.checks import check_choice, check_range
from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.emla.config import EmlaSet
from hiab_sim.emla.duty_energy import DutyOptions
from hiab_sim.emla.hold import HOLD_MODES
from hiab_sim.emla.thermal import Duty
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.yaml_fields import mapping, number

#: The keys of ``duty:`` that set the rest; a duty gives exactly one.
DUTY_REST_KEYS = ("rest_time", "cycles_per_hour", "rest_ratio")
_ONE_OF = "rest_time [s], cycles_per_hour [1/h] or rest_ratio [-]"


@dataclass(frozen=True)
class DutySettings:
    """Rest between cycles: exactly one of ``rest_time`` [s] >= 0, ``cycles_per_hour`` [1/h] > 0 or ``rest_ratio`` >= 0.

    ``rest_ratio`` r is the rest as a share of the cycle: T_rest = r T for a cycle of T [s], so every
    task of a mix rests in proportion to its own duration (r = 0.2: the cycle is 5/6 of its period,
    a 50-minute working hour).

    ``hold`` says what carries the machine during the rest (:mod:`hiab_sim.emla.hold`): ``brake``
    (the EMLAs' holding brakes), ``motor`` (the motors hold the last pose) or ``none`` (the
    seed paper's free rest, stated as a choice); None (the key omitted) is ``brake`` when every
    EMLA of the set has ``holding_brake`` data and otherwise the
    seed paper's free rest (zero torque, zero power), see :meth:`hold_mode`.
    """

    rest_time: float | None = None
    cycles_per_hour: float | None = None
    hold: str | None = None
    rest_ratio: float | None = None

    def __post_init__(self) -> None:
        if self.hold is not None:
            check_choice("duty.hold", self.hold, (*HOLD_MODES, "none"))
        given = [k for k in DUTY_REST_KEYS if getattr(self, k) is not None]
        if len(given) != 1:
            shown = " and ".join(given) if given else "{}"
            raise InvalidInputError("duty", shown, f"give exactly one of {_ONE_OF}")
        if self.rest_time is not None:
            check_range("duty.rest_time", self.rest_time, 0.0, unit="s")
        if self.cycles_per_hour is not None:
            check_range("duty.cycles_per_hour", self.cycles_per_hour, 0.0, unit="1/h", low_open=True)
        if self.rest_ratio is not None:
            check_range("duty.rest_ratio", self.rest_ratio, 0.0)

    def duty(self, cycle_time: float) -> Duty:
        """The :class:`~hiab_sim.emla.thermal.Duty` of a cycle of ``cycle_time`` [s]."""
        if self.cycles_per_hour is not None:
            return Duty.from_cycles_per_hour(cycle_time, self.cycles_per_hour)
        if self.rest_ratio is not None:
            return Duty(cycle_time, self.rest_ratio * cycle_time)
        assert self.rest_time is not None
        return Duty(cycle_time, self.rest_time)

    def hold_mode(self, emlas: EmlaSet) -> str | None:
        """The hold of the rest for ``emlas``: the given one, else ``brake`` if every EMLA has brake data, else None."""
        if self.hold is not None:
            return None if self.hold == "none" else self.hold
        return "brake" if all(p.brake is not None for p in emlas) else None

    def options(self, cycle_time: float, emlas: EmlaSet) -> DutyOptions:
        """The :class:`~hiab_sim.emla.duty_energy.DutyOptions` of a cycle of ``cycle_time`` [s] (hot windings on)."""
        return DutyOptions(self.duty(cycle_time), self.hold_mode(emlas), hot=True)

    def describe(self, cycle_time: float, emlas: EmlaSet | None = None) -> str:
        """E.g. ``60 cycles/hour (6.25 s cycle + 53.75 s rest), hold: brake``."""
        d = self.duty(cycle_time)
        if self.cycles_per_hour is not None:
            head = f"{self.cycles_per_hour:g} cycles/hour"
        elif self.rest_ratio is not None:
            head = f"rest {self.rest_ratio:g} x the cycle time"
        else:
            head = "rest between cycles"
        text = f"{head} ({d.cycle_time:g} s cycle + {d.rest_time:g} s rest)"
        if emlas is not None:
            mode = self.hold_mode(emlas)
            text += f", hold: {mode}" if mode is not None else ", rest at zero torque and zero power (no hold modelled)"
        return text


@dataclass(frozen=True)
class TransmissionOption:
    """One (gear ratio G > 1, screw lead rho > 0 [m per screw revolution]) of the catalogue."""

    gear_ratio: float
    screw_lead: float
    label: str = "transmission"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.gear_ratio) and self.gear_ratio > 1.0):
            raise InvalidInputError(f"{self.label}.gear_ratio", self.gear_ratio, "must be finite and > 1 (a reduction)")
        check_range(f"{self.label}.screw_lead", self.screw_lead, 0.0, unit="m", low_open=True)

    @property
    def transmission_ratio(self) -> float:
        """2 pi G / rho [rad/m] (eq. ``torque_force``)."""
        return 2.0 * math.pi * self.gear_ratio / self.screw_lead


@dataclass(frozen=True)
class TransmissionCatalogue:
    """Discrete transmission options per actuator, as ((actuator, (option, ...)), ...), each non-empty.

    ``actuators``: the study's actuator names the keys must be among (a crane file's, or a machine
    file's chains).
    """

    options: tuple[tuple[str, tuple[TransmissionOption, ...]], ...]
    actuators: tuple[str, ...] = ACTUATOR_NAMES

    def __post_init__(self) -> None:
        if not self.options:
            raise InvalidInputError("transmission", "{}", f"must list options for at least one of {self.actuators}")
        for name, opts in self.options:
            if name not in self.actuators:
                raise InvalidInputError("transmission", name, f"keys must be among {', '.join(self.actuators)}")
            if not opts:
                raise InvalidInputError(f"transmission.{name}", "[]", "must list at least one {gear_ratio, screw_lead}")

    @property
    def combinations(self) -> int:
        """Number of combinations (the product of the option counts)."""
        return math.prod(len(opts) for _, opts in self.options)


@dataclass(frozen=True)
class EnergySettings:
    """The three optional keys (see the module docstring)."""

    objective: str = "costf2"
    duty: DutySettings | None = None
    transmission: TransmissionCatalogue | None = None

    def __post_init__(self) -> None:
        from hiab_sim.study.nlp.objectives import check_objective_name  # the one registry

        check_objective_name(self.objective)


#: Top-level study keys this module reads.
ENERGY_KEYS = {"objective", "duty", "transmission"}


def energy_settings(top: Any, actuators: tuple[str, ...] = ACTUATOR_NAMES) -> EnergySettings:
    """Read ``objective``, ``duty`` and ``transmission`` (keyed by ``actuators``) from a study's top-level mapping."""
    objective = top.get("objective", "costf2")  # EnergySettings checks it against the objective registry
    duty = None
    if top.get("duty") is not None:
        d = dict(mapping(top["duty"], "duty", {*DUTY_REST_KEYS, "hold"}, set()))
        hold = d.pop("hold", None)
        if hold is not None and not isinstance(hold, str):
            raise InvalidInputError("duty.hold", hold, f"must be one of {', '.join((*HOLD_MODES, 'none'))}")
        duty = DutySettings(**{k: number(v, f"duty.{k}") for k, v in d.items()}, hold=hold)
    elif "duty" in top:
        raise InvalidInputError("duty", None, f"give exactly one of {_ONE_OF}")
    transmission = None
    if "transmission" in top:
        transmission = _catalogue(top["transmission"], actuators)
    return EnergySettings(objective, duty, transmission)


def _catalogue(data: Any, actuators: tuple[str, ...]) -> TransmissionCatalogue:
    if data is None:
        raise InvalidInputError("transmission", None, f"must list options for at least one of {actuators}")
    d = mapping(data, "transmission", set(actuators), set())
    options = []
    for name in actuators:
        if name not in d:
            continue
        items = d[name]
        if not isinstance(items, list):
            raise ConfigError(f"transmission.{name} must be a list of {{gear_ratio, screw_lead}}, got {items!r}")
        opts = []
        for j, item in enumerate(items):
            where = f"transmission.{name}[{j}]"
            m = mapping(item, where, {"gear_ratio", "screw_lead"}, {"gear_ratio", "screw_lead"})
            opts.append(
                TransmissionOption(
                    number(m["gear_ratio"], f"{where}.gear_ratio"),
                    number(m["screw_lead"], f"{where}.screw_lead"),
                    where,
                )
            )
        options.append((name, tuple(opts)))
    return TransmissionCatalogue(tuple(options), actuators)

"""A study's structural limits: the ``structure`` section of a study file, validated against its machine's pins.

Example for the XS 031 (every key optional; without the section no structural row enters the NLP)::

    structure:
      buckling: true                    # hold every screw's push force below P_cr / n at every sample
      buckling_safety_factor: 2.0       # n [-], default 2 (THK / NSK: 0.5 x the buckling load)
      pin_load_limits:                  # N, a pin's largest force over the motion
        lift.base_pivot: 120000.0
      min_natural_frequency_Hz: 5.0     # lowest locked-rotor frequency at every sample [Hz]

Pin names are a crane file's ``<chain>.<pin>`` with the pins of
:data:`hiab_sim.structure.pin_loads.CHAIN_PINS`, or a machine file's hinge (joint) and loop-pin names
(:func:`hiab_sim.structure.machine_structure.machine_pin_names`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from hiab_sim.checks import check_range
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.structure.buckling import DEFAULT_SAFETY_FACTOR, check_safety_factor
from hiab_sim.yaml_fields import mapping, number, positive


@dataclass(frozen=True)
class StructureSettings:
    """Structural rows of a study's NLP.

    Attributes:
        buckling: Add a buckling row per actuator with screw data at every sample.
        buckling_safety_factor: n of u = n f / P_cr <= 1 [-], in [1, 10].
        pin_load_limits_N: (pin name, largest |F| [N]) pairs; one row per pin and sample.
        min_natural_frequency_Hz: Lowest natural frequency the machine must keep at every sample [Hz], or None.

    """

    buckling: bool = False
    buckling_safety_factor: float = DEFAULT_SAFETY_FACTOR
    pin_load_limits_N: tuple[tuple[str, float], ...] = ()
    min_natural_frequency_Hz: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.buckling, bool):
            raise InvalidInputError("structure.buckling", self.buckling, "must be true or false")
        check_safety_factor(self.buckling_safety_factor)
        for name, limit in self.pin_load_limits_N:
            check_range(f"structure.pin_load_limits.{name}", limit, 0.0, low_open=True, unit="N")
        if self.min_natural_frequency_Hz is not None:
            check_range("structure.min_natural_frequency_Hz", self.min_natural_frequency_Hz, 0.0, low_open=True)

    @property
    def any_rows(self) -> bool:
        """True when at least one structural row enters the NLP."""
        return self.buckling or bool(self.pin_load_limits_N) or self.min_natural_frequency_Hz is not None

    def check_pins(self, known: Sequence[str]) -> None:
        """Raise :class:`InvalidInputError` for a limited pin not among the machine's pins ``known``."""
        for name, _ in self.pin_load_limits_N:
            if name not in known:
                raise InvalidInputError("structure.pin_load_limits", name, f"must be one of {', '.join(known)}")

    @classmethod
    def from_mapping(cls, data: Any, pin_names: Sequence[str], where: str = "structure") -> StructureSettings:
        """Build from a study's ``structure`` mapping (None: no structural rows), pin names checked on ``pin_names``."""
        if data is None:
            return cls()
        keys = {"buckling", "buckling_safety_factor", "pin_load_limits", "min_natural_frequency_Hz"}
        node = mapping(data, where, keys, set())
        buckling = node.get("buckling", False)
        if not isinstance(buckling, bool):
            raise ConfigError(f"{where}.buckling: expected true or false, got {buckling!r}")
        limits = mapping(node.get("pin_load_limits", {}), f"{where}.pin_load_limits", None, set())
        frequency = node.get("min_natural_frequency_Hz")
        settings = cls(
            buckling=buckling,
            buckling_safety_factor=number(
                node.get("buckling_safety_factor", DEFAULT_SAFETY_FACTOR), f"{where}.buckling_safety_factor"
            ),
            pin_load_limits_N=tuple(
                (str(k), positive(v, f"{where}.pin_load_limits.{k}", "N")) for k, v in limits.items()
            ),
            min_natural_frequency_Hz=None
            if frequency is None
            else positive(frequency, f"{where}.min_natural_frequency_Hz", "Hz"),
        )
        settings.check_pins(pin_names)
        return settings

"""Winding temperature of n drives carried through cycles and rests, and the resistance it sets.

First-order model of :mod:`hiab_sim.emla.thermal` (R_th winding to ambient, tau_th = R_th C_th):
C_th dT/dt = P_cu - (T - T_amb) / R_th, advanced exactly over a step h with the step's mean copper
loss P_cu = E_cu / h:

    T(h) = T_amb + (T - T_amb) exp(-h / tau_th) + R_th P_cu (1 - exp(-h / tau_th)),

and over a rest with P_cu = 0 (the brake holds). The stator resistance follows
R_s(T) = R_ref (1 + alpha (T - T_ref)) with R_ref the EMLA file's value at T_ref.
"""

from __future__ import annotations

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaParams
from hiab_sim.env.plant.config import Thermal
from hiab_sim.errors import InvalidInputError


class WindingTemperature:
    """Winding temperatures [deg C] of the drives of ``emlas`` (module docstring)."""

    def __init__(self, thermal: Thermal, emlas: tuple[EmlaParams, ...]) -> None:
        missing = [p.name for p in emlas if p.thermal is None]
        if missing:
            raise InvalidInputError(
                "thermal", ", ".join(missing), "needs the EMLA file's thermal section for every drive"
            )
        self.settings = thermal
        self.resistance_ref = np.array([p.motor.stator_resistance for p in emlas])
        self.r_th = np.array([p.thermal.thermal_resistance for p in emlas if p.thermal is not None])
        self.tau = np.array([p.thermal.time_constant for p in emlas if p.thermal is not None])
        self.ambient = np.array([p.thermal.ambient_temperature for p in emlas if p.thermal is not None])
        self.temperature = np.full(len(emlas), thermal.initial_temperature_C)
        self._decay_step, self._decay = float("nan"), np.ones(len(emlas))

    def resistance(self) -> Array:
        """R_s(T) per drive [ohm]."""
        s = self.settings
        return self.resistance_ref * (
            1.0 + s.temperature_coefficient_per_K * (self.temperature - s.reference_temperature_C)
        )

    def advance(self, copper_energy: Array, h: float) -> None:
        """Advance by h [s] with the copper loss E_cu [J] of the step."""
        if h != self._decay_step:  # exp(-h / tau_th), the same for every step of length h
            self._decay_step, self._decay = h, np.exp(-h / self.tau)
        decay = self._decay
        power = np.asarray(copper_energy, dtype=float) / h if h > 0 else 0.0
        self.temperature = self.ambient + (self.temperature - self.ambient) * decay + self.r_th * power * (1.0 - decay)

    def rest(self) -> None:
        """Cool over the rest between cycles (no copper loss)."""
        decay = np.exp(-self.settings.rest_between_cycles_s / self.tau)
        self.temperature = self.ambient + (self.temperature - self.ambient) * decay

"""The closed loop's battery energy against the result's: the drives' powers through the EMLA file's battery.

:func:`battery_entry` takes a run's mean drive power per control step through the inverters and the
battery on the shared DC bus (:func:`hiab_sim.emla.battery.battery_power`: h_inv per drive, summed,
h_bat) and sums it over the steps; :func:`predicted_battery_energy` reads the optimiser's cycle
battery energy of each design (``result.json`` ``energy.<design>.battery_energy_J``, the same model
on the plan's fine grid). Used by ``hiab-sim simulate`` and the plant's effect study
(:mod:`hiab_sim.env.effects`) for any result with an energy section.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hiab_sim.emla.config import EmlaSet
from hiab_sim.env.rollout import ClosedLoopRun

BATTERY_NOTE = (
    "battery_energy_J: the closed loop's drive powers (mean over each control step) through the EMLA file's "
    "inverters and battery on the shared DC bus (hiab_sim.emla.battery: h_inv per drive, summed, h_bat), "
    "summed over the steps; predicted_battery_energy_J: the result's cycle battery energy of the design "
    "(result.json energy.<design>.battery_energy_J, the same model on the plan's fine grid)"
)


def predicted_battery_energy(result_dir: str | Path) -> dict[str, float]:
    """The result's cycle battery energy per design [J] (empty where the result has no energy section)."""
    from hiab_sim.results.read import read_result

    energy = read_result(result_dir).energy
    if energy is None:
        return {}
    return {"initial": energy.initial.battery_energy_J, "optimal": energy.optimal.battery_energy_J}


def battery_entry(run: ClosedLoopRun, emlas: EmlaSet, predicted: float | None) -> dict[str, float | None]:
    """A run's closed-loop battery energy [J] (:data:`BATTERY_NOTE`), the prediction and their difference [%]."""
    from hiab_sim.emla.battery import battery_power

    _, p_bat, _, _ = battery_power(run.electrical_power[:-1], emlas.battery)
    energy = float(np.sum(p_bat * np.diff(run.time)))
    return {
        "battery_energy_J": energy,
        "predicted_battery_energy_J": predicted,
        "battery_energy_difference_percent": None if predicted is None else 100.0 * (energy / predicted - 1.0),
    }

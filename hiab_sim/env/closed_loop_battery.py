"""The closed loop's battery energy: the drives' logged powers through the planner's DC bus and battery.

One boundary with the planner's battery energy (``result.json``'s ``energy.<design>``) and the playback's
overlay: each drive's DC-input power passes its inverter h_inv, the drives add on the shared DC bus and
the battery delivers h_bat of the bus (:func:`hiab_sim.emla.battery.battery_power`, exact kinks). The
closed loop logs each drive's DC-input energy E_i(t_k) (``ClosedLoopRun.cumulative_energy``, inverter
loss and brake coil included); over control step k the drive's mean power is
P_i,k = (E_i(t_k+1) - E_i(t_k)) / dt_k (``ClosedLoopRun.electrical_power``), so

    E_bat(t_k) = sum_{j < k} h_bat(sum_i h_inv(P_i,j)) dt_j    [J],

which equals sum_i E_i(t_k) when every efficiency is 1. Used by ``simulation.json`` (``battery_energy_J``)
and the closed-loop video's overlay alike.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla.battery import BatteryParams, battery_power
from hiab_sim.env.rollout import ClosedLoopRun
from hiab_sim.percent import change_percent

#: What ``simulation.json`` says of its battery energies.
BATTERY_NOTE = (
    "battery_energy_J: the closed loop's drive powers (mean over each control step) through the EMLA file's "
    "inverters and battery on the shared DC bus (hiab_sim.emla.battery: h_inv per drive, summed, h_bat), "
    "summed over the steps; predicted_battery_energy_J: the result's battery energy of the design over one "
    "cycle (result.json energy.<design>.duty.cycle_battery_energy_J with the study's duty model, else "
    "energy.<design>.battery_energy_J: the same model on the plan's fine grid, the rest between cycles left out)"
)


def cumulative_battery_energy(run: ClosedLoopRun, battery: BatteryParams) -> Array:
    """E_bat(t_k) [J] at every logged time of ``run`` (module docstring), shape (N,), 0 at the start."""
    _, p_bat, _, _ = battery_power(run.electrical_power[:-1], battery)
    return np.concatenate([[0.0], np.cumsum(p_bat * np.diff(run.time))])


def predicted_cycle_battery_energy(result_dir: str | Path, task: int | None = None) -> dict[str, float]:
    """The result's battery energy of one cycle per design [J] (empty where the result has no energy section).

    ``task``: the index k of a duty mix's task, whose own cycle's energy is ``tasks[k].energy`` (the
    top-level one is the mix's per hour); None for a single-task result.
    """
    from hiab_sim.results.read import read_result

    result = read_result(result_dir)
    energy = result.energy if task is None else (result.tasks or ())[task].energy
    if energy is None:
        return {}
    return {
        name: design.battery_energy_J if design.duty is None else design.duty.cycle_battery_energy_J
        for name, design in (("initial", energy.initial), ("optimal", energy.optimal))
    }


def battery_entry(run: ClosedLoopRun, battery: BatteryParams, predicted: float | None) -> dict[str, float | None]:
    """A run's closed-loop battery energy [J] (:data:`BATTERY_NOTE`), the prediction and their difference [%]."""
    energy = float(cumulative_battery_energy(run, battery)[-1])
    return {
        "battery_energy_J": energy,
        "predicted_battery_energy_J": predicted,
        "battery_energy_difference_percent": None if predicted is None else change_percent(predicted, energy),
    }


def battery_notes(run: ClosedLoopRun, battery: BatteryParams, at: Array) -> tuple[str, ...]:
    """Per-frame overlay texts at times ``at`` [s]: the time and the battery energy so far of this cycle [kJ].

    The playback's wording (:func:`hiab_sim.render.video.energy_notes`), with the energy taken so far
    against the cycle's total, which is ``battery_entry``'s ``battery_energy_J``; each frame shows the
    value at the first logged time at or after it, the sample whose pose the video draws.
    """
    energy = cumulative_battery_energy(run, battery)
    total = float(energy[-1]) / 1e3
    index = np.clip(np.searchsorted(run.time, at), 0, len(run.time) - 1)
    return tuple(
        f"t = {t:5.2f} s   battery energy {energy[k] / 1e3:.3f} of {total:.3f} kJ per cycle (at the battery)"
        for t, k in zip(at, index, strict=True)
    )

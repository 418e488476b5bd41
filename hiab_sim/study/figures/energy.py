"""Figure of a result's energy sections: the EMLAs against the hydraulic cylinders they replace.

Draws :func:`hiab_sim.hydraulics.figure.plot_energy_comparison` for the optimal design from the
result alone: the battery and per-drive energies of ``result.energy`` and both supplies of
``result.hydraulic_baseline`` (nothing is recomputed here).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hiab_sim.figure_io import save_png
from hiab_sim.hydraulics.figure import plot_energy_comparison
from hiab_sim.results.energy_sections import HydraulicVariant
from hiab_sim.results.schema import Result


@dataclass(frozen=True)
class _Supply:
    """A supply variant of the result as the figure reads it: total and per-actuator input [J]."""

    input_energy: float
    input_energy_per_actuator: np.ndarray


def _supply(variant: HydraulicVariant, names: list[str]) -> _Supply:
    per = variant.input_energy_per_actuator_J
    return _Supply(variant.input_energy_J, np.array([per[name] for name in names]))


def hydraulic_figure(path: Path, result: Result) -> list[Path]:
    """Write the EMLA-vs-hydraulic charts of the optimal design to ``path``; [] without both sections.

    The EMLA bar is the battery energy of the cycle alone [J] (the rest of a duty period excluded), the
    period the hydraulic bars cover.
    """
    energy, baseline = result.energy, result.hydraulic_baseline
    if energy is None or baseline is None:
        return []
    names = list(energy.optimal.drawn_energy_J)
    drawn = np.array([energy.optimal.drawn_energy_J[name] for name in names])
    design = baseline.optimal
    title = f"{result.name}, optimal design: EMLAs against the crane's hydraulic cylinders, same motion and loads"
    fig = plot_energy_comparison(
        names,
        drawn,
        design.emla_cycle_battery_energy_J
        if design.emla_cycle_battery_energy_J is not None
        else design.emla_battery_energy_J,
        _supply(design.constant_pressure, names),
        _supply(design.load_sensing, names),
        title,
    )
    return [save_png(fig, path)]

"""Figure: the EMLAs' energy against the hydraulic baseline (both supply variants), one boundary per chart.

Left, the whole machine at its energy source: the battery energy of the EMLAs (shared DC bus,
regeneration credited, :mod:`hiab_sim.emla.battery`) against the electrical input of the pump's
motor for each supply. Right, per actuator at its own supply: each EMLA drive's electrical input
int max(P_i, 0) dt (no regeneration credited) against the pump input attributed to that cylinder,
int p_pump Q_i dt / (eta_pump eta_motor). The two charts are not summed into each other: the
battery credits one drive's regeneration to another, the per-drive bars do not.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from hiab_sim.errors import InvalidInputError
from hiab_sim.figure_io import new_figure
from hiab_sim.style import colour

#: Colours of the three energy sources (EMLA: the optimal design's colour; hydraulics: the warm one, two shades).
_EMLA = colour("optimal")
_LOAD_SENSING = colour("hydraulic")
_CONSTANT_PRESSURE = "#8C3A00"  # a darker vermillion: the same family as the hydraulic baseline


class SupplyEnergy(Protocol):
    """A hydraulic supply's energy over the cycle: total [J] and per cylinder [J] (summing to it)."""

    @property
    def input_energy(self) -> float:
        """Energy into the pump's motor over the cycle [J]."""
        ...

    @property
    def input_energy_per_actuator(self) -> ArrayLike:
        """The part of it attributed to each cylinder [J], (n,)."""
        ...


def plot_energy_comparison(
    names: Sequence[str],
    emla_drawn: ArrayLike,
    battery_energy: float,
    constant_pressure: SupplyEnergy,
    load_sensing: SupplyEnergy,
    title: str = "",
) -> Figure:
    """Two charts [kJ]: the machine at its source (left) and each actuator at its supply (right).

    Args:
        names: Actuator names, length n.
        emla_drawn: Electrical input of each EMLA drive without regeneration [J], shape (n,).
        battery_energy: Battery energy of the cycle [J].
        constant_pressure: Constant-pressure baseline.
        load_sensing: Load-sensing baseline.
        title: Figure title.

    """
    drawn = np.asarray(emla_drawn, dtype=float)
    n = len(names)
    cp_each = np.asarray(constant_pressure.input_energy_per_actuator, dtype=float)
    ls_each = np.asarray(load_sensing.input_energy_per_actuator, dtype=float)
    if drawn.shape != (n,) or cp_each.shape != (n,) or ls_each.shape != (n,):
        raise InvalidInputError("emla_drawn", f"shape {drawn.shape}", f"must be ({n},) like the baselines")
    fig = new_figure((10.0, 4.4))
    whole, each = fig.subplots(1, 2, width_ratios=(1.0, 1.6))
    totals = (
        ("EMLAs: battery", battery_energy, _EMLA),
        ("hydraulic, load sensing: pump motor input", load_sensing.input_energy, _LOAD_SENSING),
        ("hydraulic, constant pressure: pump motor input", constant_pressure.input_energy, _CONSTANT_PRESSURE),
    )
    for k, (label, value, shade) in enumerate(totals):
        bars = whole.bar([k], [value / 1e3], 0.7, color=shade, label=label)
        whole.bar_label(bars, fmt="%.1f", fontsize=8)
    whole.set_xticks(range(3), ["EMLA\nbattery", "hydraulic\nload sensing", "hydraulic\nconstant\npressure"])
    whole.set_ylabel("energy per cycle [kJ]")
    whole.set_title("Whole machine, at its energy source", fontsize=10)
    x = np.arange(n)
    width = 0.27
    series = (
        ("EMLA drive input (no regeneration credited)", drawn, _EMLA),
        ("hydraulic, load sensing: pump input for this cylinder", ls_each, _LOAD_SENSING),
        ("hydraulic, constant pressure: pump input for this cylinder", cp_each, _CONSTANT_PRESSURE),
    )
    for j, (label, values, shade) in enumerate(series):
        bars = each.bar(x + (j - 1) * width, values / 1e3, width, label=label, color=shade)
        each.bar_label(bars, fmt="%.1f", fontsize=7)
    each.set_xticks(x, list(names))
    each.set_ylabel("energy per cycle [kJ]")
    each.set_title("Each actuator, at its own supply (not summed: see the left chart)", fontsize=10)
    each.legend(fontsize=7, frameon=False, loc="upper left")
    each.margins(y=0.35)  # room for the legend above the bars
    whole.margins(y=0.15)
    for ax in (whole, each):
        ax.grid(alpha=0.3, axis="y")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig

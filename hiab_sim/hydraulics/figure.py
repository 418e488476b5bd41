"""Figure: energy per actuator of the EMLAs against the hydraulic baseline (both supply variants)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from hiab_sim.errors import InvalidInputError
from hiab_sim.hydraulics.baseline import SupplyResult


def plot_energy_comparison(
    names: Sequence[str],
    emla_drawn: ArrayLike,
    battery_energy: float,
    constant_pressure: SupplyResult,
    load_sensing: SupplyResult,
    title: str = "",
) -> Figure:
    """Grouped bars [kJ] per actuator and in total: EMLA vs hydraulic energy for the same motion.

    Per actuator the EMLA bar is its drawn electrical energy int max(P_i, 0) dt (no regeneration
    credited) and the hydraulic bars the pump input attributed to that cylinder,
    int p_pump Q_i dt / (eta_pump eta_motor). The total group compares the battery energy (shared
    DC bus, regeneration credited, :mod:`hiab_sim.emla.battery`) with the pumps' input energies.

    Args:
        names: Actuator names, length n.
        emla_drawn: Drawn energy per actuator [J], shape (n,).
        battery_energy: Battery energy of the cycle [J].
        constant_pressure: Constant-pressure baseline.
        load_sensing: Load-sensing baseline.
        title: Axes title.

    """
    drawn = np.asarray(emla_drawn, dtype=float)
    n = len(names)
    if drawn.shape != (n,) or constant_pressure.input_energy_per_actuator.shape != (n,):
        raise InvalidInputError("emla_drawn", f"shape {drawn.shape}", f"must be ({n},) like the baselines")
    groups = [*names, "total"]
    series = (
        ("EMLA (drawn; total: battery)", np.r_[drawn, battery_energy], "tab:green"),
        (
            "hydraulic, load sensing",
            np.r_[load_sensing.input_energy_per_actuator, load_sensing.input_energy],
            "tab:blue",
        ),
        (
            "hydraulic, constant pressure",
            np.r_[constant_pressure.input_energy_per_actuator, constant_pressure.input_energy],
            "tab:red",
        ),
    )
    fig = Figure(figsize=(7.0, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    x = np.arange(len(groups))
    width = 0.27
    for j, (label, values, colour) in enumerate(series):
        bars = ax.bar(x + (j - 1) * width, values / 1e3, width, label=label, color=colour)
        ax.bar_label(bars, fmt="%.1f", fontsize=7)
    ax.set_xticks(x, groups)
    ax.set_ylabel("energy per cycle [kJ]")
    ax.set_title(title or "EMLA vs hydraulic cylinders, same motion and loads", fontsize=9)
    ax.legend(fontsize=8, frameon=False)
    return fig

"""Figure of the price of robustness (:class:`~hiab_sim.results.schema.CrossEvaluation`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.percent import change_percent
from hiab_sim.results.analysis_sections import CrossEvaluation


def cross_figure(cross: CrossEvaluation, path: Path) -> None:
    """Bars: each design's mix net energy over the mix optimum's [J]; matrix: net energy per task over the best [%]."""
    fig = new_figure((10.0, 4.0))
    ax1, ax2 = fig.subplots(1, 2)
    lost = [np.nan if v is None else v for v in cross.mix_energy_lost_J]
    bars = ax1.bar(range(len(lost)), lost, color=["tab:gray"] * (len(lost) - 1) + ["tab:red"])
    ax1.bar_label(bars, labels=["n/a" if np.isnan(v) else f"{v:+.1f} J" for v in lost])
    ax1.axhline(0.0, color="k", linewidth=0.8)
    ax1.set_xticks(range(len(lost)), cross.designs, rotation=20, ha="right")
    ax1.set_ylabel("mix net energy over the mix optimum [J]")
    ax1.set_title("price of a single-task design on the mix (weighted)")
    matrix = np.array([[np.nan if v is None else v for v in row] for row in cross.net_energy_J], dtype=float)
    relative = change_percent(np.nanmin(matrix, axis=0), matrix)
    image = ax2.imshow(relative, cmap="viridis")
    for (i, j), value in np.ndenumerate(relative):
        ax2.text(j, i, "n/a" if np.isnan(value) else f"+{value:.3f} %", ha="center", va="center", color="w")
    ax2.set_xticks(range(len(cross.tasks)), cross.tasks, rotation=20, ha="right")
    ax2.set_yticks(range(len(cross.designs)), cross.designs)
    ax2.set_title("net energy per task over the best design [%]")
    fig.colorbar(image, ax=ax2)
    save_png(fig, path)

"""Figure of the price of robustness (:class:`~hiab_sim.study.result.CrossEvaluation`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hiab_sim.study.figures import _figure, _save
from hiab_sim.study.result import CrossEvaluation


def cross_figure(cross: CrossEvaluation, path: Path) -> None:
    """Bars of the mix's net energy per design and the designs x tasks matrix of net energy (relative to the best)."""
    fig = _figure((10.0, 4.0))
    ax1, ax2 = fig.subplots(1, 2)
    values = [np.nan if v is None else v / 1e3 for v in cross.mix_net_energy_J]
    ax1.bar(range(len(values)), values, color=["tab:gray"] * (len(values) - 1) + ["tab:red"])
    ax1.set_xticks(range(len(values)), cross.designs, rotation=20, ha="right")
    ax1.set_ylabel("mix net energy (weighted) [kJ]")
    ax1.set_title("design evaluated on the mix")
    matrix = np.array([[np.nan if v is None else v for v in row] for row in cross.net_energy_J], dtype=float)
    relative = 100.0 * (matrix / np.nanmin(matrix, axis=0) - 1.0)
    image = ax2.imshow(relative, cmap="viridis")
    for (i, j), value in np.ndenumerate(relative):
        ax2.text(j, i, "n/a" if np.isnan(value) else f"+{value:.1f} %", ha="center", va="center", color="w")
    ax2.set_xticks(range(len(cross.tasks)), cross.tasks, rotation=20, ha="right")
    ax2.set_yticks(range(len(cross.designs)), cross.designs)
    ax2.set_title("net energy per task over the best design [%]")
    fig.colorbar(image, ax=ax2)
    _save(fig, path)

"""Summary figures of a sweep table: the net-energy saving and the optimal net energy against each parameter."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd

from hiab_sim.atomic_io import write_atomic


def summary_figures(frame: pd.DataFrame, parameters: list[str], out: Path, title: str) -> list[Path]:
    """Write ``sweep_summary.png`` (saving and energy vs each numeric parameter) and, for two, a saving map."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    numeric = [p for p in parameters if pd.api.types.is_numeric_dtype(frame[p])]
    if not numeric or frame.empty:
        return []
    ok = frame["status"] == "ok"
    fig, axes = plt.subplots(2, len(numeric), figsize=(4.6 * len(numeric), 7), squeeze=False, constrained_layout=True)
    for col, p in enumerate(numeric):
        others = [q for q in numeric if q != p]
        colour = frame.loc[ok, others[0]] if others else None
        for row, (y, label) in enumerate(
            (("net_energy_saved_percent", "net energy saved [%]"), ("opt_net_energy_J", "optimal net energy [kJ]"))
        ):
            ax = axes[row, col]
            scale = 1e-3 if y.endswith("_J") else 1.0
            style = {"c": colour, "cmap": "viridis"} if colour is not None else {"c": "C0"}
            sc = ax.scatter(frame.loc[ok, p], frame.loc[ok, y] * scale, s=36, **style)
            if (~ok).any():
                bottom = np.nanmin(frame.loc[ok, y] * scale) if ok.any() else 0.0
                ax.scatter(frame.loc[~ok, p], np.full((~ok).sum(), bottom), marker="x", c="red", label="failed")
                ax.legend(fontsize=8)
            if others and row == 0:
                fig.colorbar(sc, ax=ax, label=others[0])
            ax.set_xlabel(p)
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
    fig.suptitle(f"{title}: {int(ok.sum())} of {len(frame)} points optimised")
    paths = [out / "sweep_summary.png"]
    _save(fig, paths[0])
    if len(numeric) == 2 and ok.any():
        xs, ys = np.sort(frame[numeric[0]].unique()), np.sort(frame[numeric[1]].unique())
        saved = np.full((len(ys), len(xs)), np.nan)  # every point of the grid, failed ones left blank
        for _, row in frame[ok].iterrows():
            saved[np.searchsorted(ys, row[numeric[1]]), np.searchsorted(xs, row[numeric[0]])] = row[
                "net_energy_saved_percent"
            ]
        fig, ax = plt.subplots(figsize=(6.4, 4.8), constrained_layout=True)
        mesh = ax.pcolormesh(xs, ys, np.ma.masked_invalid(saved), shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="net energy saved [%]")
        for (yi, xi), v in np.ndenumerate(saved):
            if np.isfinite(v):
                ax.text(float(xs[xi]), float(ys[yi]), f"{v:.1f}", ha="center", va="center", fontsize=8, c="w")
        for _, row in frame[~ok].iterrows():
            ax.text(row[numeric[0]], row[numeric[1]], "failed", ha="center", va="center", fontsize=8, c="red")
        ax.set_xlabel(numeric[0])
        ax.set_ylabel(numeric[1])
        ax.set_title(f"{title}\nnet energy saved [%] (failed: no feasible start, or the solver)", fontsize=10)
        paths.append(out / "sweep_saving_map.png")
        _save(fig, paths[1])
    return paths


def _save(fig: object, path: Path) -> None:
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)  # type: ignore[attr-defined]
    plt.close(fig)  # type: ignore[arg-type]
    write_atomic(path, buffer.getvalue())

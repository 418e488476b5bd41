"""Summary figures of a sweep table: the net-energy saving and the optimal net energy against each parameter.

Failed points (no feasible start, or the solver failed) have no energy: they are drawn as red
crosses on a strip above each axes (outside the data's range), never at a value that would read as data.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from hiab_sim.figure_io import new_figure, save_png

#: Failed points: red crosses on a strip at this height of the axes (axes fraction, above the data).
FAILED_STRIP = 1.05


def _words(parameter: str) -> str:
    """A sweep axis (``payload``, ``lift.gear_ratio``) as a label: dots and underscores as spaces."""
    return parameter.replace(".", " ").replace("_", " ")


def summary_figures(frame: pd.DataFrame, parameters: list[str], out: Path, title: str) -> list[Path]:
    """Write ``sweep_summary.png`` (saving and energy vs each numeric parameter) and, for two, a saving map."""
    numeric = [p for p in parameters if pd.api.types.is_numeric_dtype(frame[p])]
    if not numeric or frame.empty:
        return []
    ok = frame["status"] == "ok"
    fig = new_figure((4.6 * len(numeric), 7.4))
    axes = fig.subplots(2, len(numeric), squeeze=False)
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
                ax.scatter(
                    frame.loc[~ok, p], np.full(int((~ok).sum()), FAILED_STRIP), marker="x", c="red", clip_on=False,
                    transform=ax.get_xaxis_transform(), label=f"failed ({int((~ok).sum())}): no result",
                )  # fmt: skip
                ax.legend(fontsize=8, loc="best")
                ax.set_title(" ", fontsize=8, pad=10)  # keeps the strip clear of the figure title
            values = frame[p].to_numpy(dtype=float)  # failed points included: their x must be on the axis
            span = max(float(np.ptp(values)), 1e-12)
            ax.set_xlim(values.min() - 0.06 * span, values.max() + 0.06 * span)
            if others and row == 0:
                fig.colorbar(sc, ax=ax, label=_words(others[0]))
            ax.set_xlabel(_words(p))
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
    fig.suptitle(f"{title}: {int(ok.sum())} of {len(frame)} points optimised (red crosses above an axes: failed)")
    paths = [save_png(fig, out / "sweep_summary.png")]
    if len(numeric) == 2 and ok.any():
        xs, ys = np.sort(frame[numeric[0]].unique()), np.sort(frame[numeric[1]].unique())
        saved = np.full((len(ys), len(xs)), np.nan)  # every point of the grid, failed ones left blank
        for _, row in frame[ok].iterrows():
            saved[np.searchsorted(ys, row[numeric[1]]), np.searchsorted(xs, row[numeric[0]])] = row[
                "net_energy_saved_percent"
            ]
        fig = new_figure((6.4, 4.8))
        ax = fig.add_subplot()
        mesh = ax.pcolormesh(xs, ys, np.ma.masked_invalid(saved), shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="net energy saved [%]")
        for (yi, xi), v in np.ndenumerate(saved):
            if np.isfinite(v):
                ax.text(float(xs[xi]), float(ys[yi]), f"{v:.1f}", ha="center", va="center", fontsize=8, c="w")
        for _, row in frame[~ok].iterrows():
            ax.text(row[numeric[0]], row[numeric[1]], "failed", ha="center", va="center", fontsize=8, c="red")
        ax.set_xlabel(_words(numeric[0]))
        ax.set_ylabel(_words(numeric[1]))
        ax.set_title(f"{title}\nnet energy saved [%] (failed: no feasible start, or the solver)", fontsize=10)
        paths.append(save_png(fig, out / "sweep_saving_map.png"))
    return paths

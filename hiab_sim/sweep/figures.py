"""Summary figures of a sweep table: the energy saving and the energy at the optimum against each parameter.

Both rows are at one boundary, the answer's (:func:`hiab_sim.sweep.answers.energy_columns`): the battery
energy where every finished point has it, else the motors' net electrical energy. Axes are labelled in
words with their units (:func:`axis_words`). Failed points (no feasible start, or the solver failed)
have no energy: they are drawn as red crosses on a strip above each axes (outside the data's range),
never at a value that would read as data.
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd

from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.percent import saving_percent
from hiab_sim.study.report.summary import BATTERY_BOUNDARY, LENGTH_WORDS
from hiab_sim.sweep.answers import energy_columns

#: Failed points: red crosses on a strip at this height of the axes (axes fraction, above the data).
FAILED_STRIP = 1.05
_GEAR = re.compile(r"^emla\.(\w+)\.gear_ratio$")
_BOUND = re.compile(r"^bounds\.(\w+)\.(low|up)\[(\d)\]$")
_LENGTH_FIELDS = ("L", "Lc0", "Lc")
_PER_ACTUATOR = re.compile(r"^(brake|thermal)\.(\w+) (.*)$")


def axis_words(parameter: str) -> str:
    """A sweep axis (a study path such as ``payload``, ``emla.lift.gear_ratio``, or a zipped axis's name) as a label.

    Known study paths carry their unit (payload [kg], a gear ratio [-], a length bound [m]); a name
    ending in ``_percent`` gets [%]; any other keeps its words, dots and underscores as spaces.
    """
    if parameter == "payload":
        return "payload at the tool point [kg]"
    match = _GEAR.match(parameter)
    if match:
        return f"{match.group(1)} EMLA gear ratio, motor per screw turns [-]"
    match = _BOUND.match(parameter)
    if match and int(match.group(3)) < len(_LENGTH_FIELDS):
        chain, side, index = match.groups()
        length = _LENGTH_FIELDS[int(index)]
        side_words = "lower" if side == "low" else "upper"
        return f"{chain} {length} ({LENGTH_WORDS[length]}): {side_words} bound [m]"
    words = parameter.replace(".", " ").replace("_", " ")
    return words.removesuffix(" percent") + " [%]" if words.endswith(" percent") else words


def failed_reason(message: str) -> str:
    """Why a point failed, in words, from its table message (the feasibility phase names the binding row).

    The text after the least-violation point (``...m): <row> ...``): its own words after ``": "`` where
    the row gives them ("the TCP leaves its tracking band by 9 % of the band"), else the row with its
    actuator first ("brake.lift holding torque ..." -> "lift brake holding torque ..."); a message of
    another form keeps its last clause.
    """
    tail = message.rsplit("): ", 1)[-1]
    if ": " in tail:
        return tail.split(": ", 1)[1]
    match = _PER_ACTUATOR.match(tail)
    if match:
        kind, actuator, rest = match.groups()
        return f"{actuator} {'brake' if kind == 'brake' else 'motor'} {rest}"
    return tail.replace("_", " ")


def summary_figures(
    frame: pd.DataFrame, parameters: list[str], out: Path, title: str, per: str = "cycle"
) -> list[Path]:
    """Write ``sweep_summary.png`` (saving and energy vs each numeric parameter) and, for two, a saving map.

    ``per`` names the period the battery energy covers (``"cycle"``, or ``"duty period"`` with the
    study's duty model); the net electrical energy is always per cycle.
    """
    numeric = [p for p in parameters if pd.api.types.is_numeric_dtype(frame[p])]
    if not numeric or frame.empty:
        return []
    ok = frame["status"] == "ok"
    column, start_column, boundary = energy_columns(frame, ok)
    battery = boundary == BATTERY_BOUNDARY
    what = "battery energy" if battery else "net electrical energy"
    period = per if battery else "cycle"
    saved = saving_percent(frame[start_column].astype(float), frame[column].astype(float))
    rows = (
        (saved, f"{what} saved by the\noptimisation [%]"),
        (frame[column].astype(float) * 1e-3, f"{what} at the optimum\n[kJ per {period}]"),
    )
    fig = new_figure((4.8 * len(numeric) + 0.8, 7.4))
    axes = fig.subplots(2, len(numeric), squeeze=False)
    for col, p in enumerate(numeric):
        others = [q for q in numeric if q != p]
        colour = frame.loc[ok, others[0]] if others else None
        for row, (values_y, label) in enumerate(rows):
            ax = axes[row, col]
            style = {"c": colour, "cmap": "viridis"} if colour is not None else {"c": "C0"}
            sc = ax.scatter(frame.loc[ok, p], values_y[ok], s=36, **style)
            if (~ok).any():  # one cross per x on the strip, with the count where several failed there
                at, count = np.unique(frame.loc[~ok, p].to_numpy(dtype=float), return_counts=True)
                ax.scatter(
                    at, np.full(len(at), FAILED_STRIP), marker="x", c="red", clip_on=False,
                    transform=ax.get_xaxis_transform(), label=f"failed ({int((~ok).sum())}): no result",
                )  # fmt: skip
                for x, n in zip(at, count, strict=True):
                    if n > 1:
                        ax.annotate(f"{n}", (x, FAILED_STRIP), xycoords=ax.get_xaxis_transform(), xytext=(5, 0),
                                    textcoords="offset points", va="center", fontsize=8, c="red")  # fmt: skip
                ax.legend(fontsize=8, loc="best")
                ax.set_title(" ", fontsize=8, pad=10)  # keeps the strip clear of the figure title
            values = frame[p].to_numpy(dtype=float)  # failed points included: their x must be on the axis
            span = max(float(np.ptp(values)), 1e-12)
            ax.set_xlim(values.min() - 0.06 * span, values.max() + 0.06 * span)
            if others and row == 0:
                fig.colorbar(sc, ax=ax, label=axis_words(others[0]))
            ax.set_xlabel(axis_words(p))
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
    failed = "; red crosses above an axes: failed points (how many, where more than one)" if (~ok).any() else ""
    fig.suptitle(f"{title}: {int(ok.sum())} of {len(frame)} points optimised{failed}\nenergies {boundary}", fontsize=10)
    paths = [save_png(fig, out / "sweep_summary.png")]
    if len(numeric) == 2 and ok.any():
        xs, ys = np.sort(frame[numeric[0]].unique()), np.sort(frame[numeric[1]].unique())
        grid = np.full((len(ys), len(xs)), np.nan)  # every point of the grid, failed ones left blank
        for k, row_ in frame[ok].iterrows():
            grid[np.searchsorted(ys, row_[numeric[1]]), np.searchsorted(xs, row_[numeric[0]])] = saved[k]
        fig = new_figure((7.6, 5.6))
        ax = fig.add_subplot()
        mesh = ax.pcolormesh(xs, ys, np.ma.masked_invalid(grid), shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label=f"{what} saved by the optimisation [%]")
        for (yi, xi), v in np.ndenumerate(grid):
            if np.isfinite(v):
                ax.text(float(xs[xi]), float(ys[yi]), f"{v:.1f} %", ha="center", va="center", fontsize=9, c="w",
                        bbox={"boxstyle": "round", "fc": (0.0, 0.0, 0.0, 0.35), "lw": 0})  # fmt: skip
        for _, row_ in frame[~ok].iterrows():  # no value: why, in words
            why = textwrap.fill(failed_reason(str(row_["message"])), 26)
            ax.text(row_[numeric[0]], row_[numeric[1]], f"failed:\n{why}", ha="center", va="center", fontsize=6.5,
                    c="red")  # fmt: skip
        ax.set_xticks(xs)
        ax.set_yticks(ys)
        ax.set_xlabel(axis_words(numeric[0]))
        ax.set_ylabel(axis_words(numeric[1]))
        ax.set_title(
            f"{title}: {what} saved by the optimisation [%]\n{boundary}\nfailed: no feasible start (the limit "
            "broken least named) or the solver",
            fontsize=9,
        )
        paths.append(save_png(fig, out / "sweep_saving_map.png"))
    return paths

"""Files of an energy map: the figure (objective and net energy, infeasible cells by binding constraint), NPZ, JSON."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiab_sim.atomic_io import write_atomic
from hiab_sim.sweep.energy_map import FEASIBILITY_TOLERANCE, EnergyMap

TRAJECTORY_NOTE = (
    "joint trajectory of every task fixed at the base design's (the optimum's spline or the start's "
    "inverse-kinematics fit); tracking, joint-range and joint-velocity rows depend on it only and hold over the "
    "whole map"
)


#: The objectives in words, for axis labels (names of :data:`hiab_sim.study.nlp.objectives.OBJECTIVES`).
OBJECTIVE_AXIS = {"costf2": "squared-power cost", "battery_energy": "battery energy"}


def variable_words(name: str) -> str:
    """A decision variable (``lift.L``) as a label in words with its unit (``lift L, base pivot to boom hinge [m]``)."""
    from hiab_sim.study.report.summary import LENGTH_WORDS

    chain, _, field = name.partition(".")
    words = LENGTH_WORDS.get(field)
    return f"{chain} {field}, {words} [m]" if words else f"{name.replace('.', ' ')} [m]"


def objective_words(m: EnergyMap) -> str:
    """The map's objective and its unit in words, weighted over the tasks of a mix."""
    if len(m.tasks) == 1:
        return f"{m.objective} [{m.objective_unit}]"
    parts = " + ".join(f"{w:g} x {name}" for name, w in m.tasks)
    return f"{m.objective} weighted over the tasks ({parts}) [{m.objective_unit} per unit of the weights]"


def energy_words(m: EnergyMap) -> str:
    """What an energy of the map is counted over: a cycle, or the weighted tasks of a mix."""
    if len(m.tasks) == 1:
        return "per cycle"
    return "weighted over the tasks (" + " + ".join(f"{w:g} x {name}" for name, w in m.tasks) + ")"


def summary(m: EnergyMap) -> dict[str, Any]:
    """JSON-ready summary: variables, base design, trajectory note, value at the base, best feasible cells.

    ``best_feasible_cell`` has the least study objective, ``least_battery_energy_cell`` the least
    battery energy (the same cell for a study whose objective is the battery energy, up to its
    smoothing); None without a feasible cell.
    """
    v = m.values
    feasible = v.feasible

    def cell_values(k: int) -> dict[str, Any]:
        return {
            "xi_m": v.xi[k].tolist(),
            "objective": float(v.objective[k]),
            "objective_value": float(v.objective_value[k]),
            "costf2_W2s": float(v.costf2[k]),
            "net_electrical_energy_J": float(v.net_energy[k]),
            "battery_energy_J": float(v.battery_energy[k]),
            "binding_constraint": v.names[int(v.binding[k])],
            "smallest_margin": float(v.margins[k].min()),
        }

    best: dict[str, Any] | None = None
    least: dict[str, Any] | None = None
    if feasible.any():
        best = cell_values(int(np.flatnonzero(feasible)[np.argmin(v.objective[feasible])]))
        least = cell_values(int(np.flatnonzero(feasible)[np.argmin(v.battery_energy[feasible])]))
    counts: dict[str, int] = {}
    for cell in np.flatnonzero(~feasible):
        name = v.names[int(v.binding[cell])]
        counts[name] = counts.get(name, 0) + 1
    b = m.at_base
    return {
        "variables": list(m.variables),
        "axes_m": [a.tolist() for a in m.axes],
        "base": m.base.source,
        "base_xi_m": m.base.xi.tolist(),
        "design_variables": list(m.design_names),
        "fixed": {name: float(m.base.xi[i]) for i, name in enumerate(m.design_names) if name not in m.variables},
        "tasks": [{"name": name, "weight": w} for name, w in m.tasks],
        "trajectory": TRAJECTORY_NOTE,
        "objective_name": m.objective,
        "objective_unit": m.objective_unit,
        "objective_note": (
            f"objective: the study's {objective_words(m)} on the collocation grid divided by its value at the "
            "study's start; objective_value: the same in its unit; costf2_W2s: the paper's squared-power cost "
            "(whatever the objective); energies " + energy_words(m)
        ),
        "at_base": {
            "objective": float(b.objective[0]),
            "objective_value": float(b.objective_value[0]),
            "costf2_W2s": float(b.costf2[0]),
            "net_electrical_energy_J": float(b.net_energy[0]),
            "drawn_energy_summed_drives_J": float(b.drawn_energy[0]),
            "battery_energy_J": float(b.battery_energy[0]),
            "smallest_margin": float(b.margins.min()),
            "binding_constraint": b.names[int(b.binding[0])],
        },
        "feasible_cells": int(feasible.sum()),
        "cells": len(feasible),
        "feasibility_tolerance": FEASIBILITY_TOLERANCE,
        "best_feasible_cell": best,
        "least_battery_energy_cell": least,
        "infeasible_cells_by_binding_constraint": counts,
        "battery_energy_note": "energy the battery delivers through the shared DC bus (hiab_sim.emla.battery)",
    }


def write_map(m: EnergyMap, out: Path, per: str = "cycle") -> list[Path]:
    """Write energy_map.json, energy_map.npz and energy_map.png into ``out`` (atomically); return the paths.

    ``per`` names the period the battery energy covers (``"cycle"``, or ``"duty period"`` with the
    study's duty model), for the figure's label.
    """
    out.mkdir(parents=True, exist_ok=True)
    v = m.values
    arrays = {
        "axis0_m": m.axes[0],
        "axis1_m": m.axes[1],
        "objective": m.grid(v.objective),
        "objective_value": m.grid(v.objective_value),
        "costf2_W2s": m.grid(v.costf2),
        "net_energy_J": m.grid(v.net_energy),
        "drawn_energy_J": m.grid(v.drawn_energy),
        "battery_energy_J": m.grid(v.battery_energy),
        "feasible": m.grid(v.feasible),
        "binding": m.grid(v.binding),
        "smallest_margin": m.grid(v.margins.min(axis=1)),
        "constraint_names": np.array(v.names),
    }
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)  # type: ignore[arg-type]
    paths = [out / "energy_map.json", out / "energy_map.npz", out / "energy_map.png"]
    write_atomic(paths[0], json.dumps(summary(m), indent=2) + "\n")
    write_atomic(paths[1], buffer.getvalue())
    write_atomic(paths[2], figure_png(m, per))
    return paths


#: Limits named beside the most frequent one in an infeasible map's note (the rest are counted, listed in the JSON).
OTHER_LIMITS = 2


def infeasible_note(m: EnergyMap, with_others: bool = True) -> str | None:
    """Why cells are infeasible, in words: the most frequent binding limit (then the others') and what to map instead.

    None when most cells are feasible. ``with_others``: also the next limits with their counts (the console;
    the figure's legend colours every limit, so its note leaves them out). The hint names the other decision
    variables of the chain the binding limit belongs to (they move that limit), else the two variables of the
    map with wider bounds.
    """
    from hiab_sim.study.report.summary import limit_in_words

    v = m.values
    feasible = np.asarray(v.feasible, dtype=bool)
    if feasible.mean() >= 0.5:
        return None
    binding = np.asarray(v.binding)[~feasible]
    names, counts = np.unique(binding, return_counts=True)
    # most cells first; a tie keeps the row order (np.unique's, ascending), as argmax would
    (share, first), *rest = sorted(zip(counts.tolist(), names.tolist(), strict=True), key=lambda c: -c[0])
    top = v.names[int(first)]
    chain = top.split(".")[1] if top.count(".") >= 2 else ""
    others = [x for x in m.design_names if x.startswith(f"{chain}.") and x not in m.variables] if chain else []
    hint = (
        f"map {' and '.join(others[:2])} instead ({'they move' if len(others[:2]) > 1 else 'it moves'} this limit)"
        if others
        else "widen the bounds of the mapped variables, or map the lengths of the chain that binds"
    )
    count = int(feasible.sum())
    head = "no feasible cell" if count == 0 else f"only {count} feasible cell{'' if count == 1 else 's'}"
    also = "; ".join(f"{n} break {limit_in_words(v.names[int(k)], detail=False)}" for n, k in rest[:OTHER_LIMITS])
    hidden = len(rest) - OTHER_LIMITS
    more = f" and {hidden} more limit{'s' if hidden > 1 else ''} (energy_map.json)" if hidden > 0 else ""
    return (
        f"{head} of {feasible.size}: {share} cells break {limit_in_words(top)} "
        f"with the other decision variables fixed at the {m.base.source.split(' (')[0]}"
        + (f" (the other cells: {also}{more})" if rest and with_others else "")
        + f";\n{hint}"
    )


def figure_png(m: EnergyMap, per: str = "cycle") -> bytes:
    """PNG of two panels (objective, battery energy per ``per``) with infeasible cells coloured by binding constraint.

    One quantity and one boundary per panel: the study's objective relative to its start, and the
    battery energy (at the battery: shared DC bus, regeneration credited), the boundary of the answer.

    Where most cells are infeasible, a note in the figure says which limit binds and which
    variables to map instead (:func:`infeasible_note`); without a feasible cell there are no values
    to show: one panel shows the limit each cell breaks, with no colour bar.
    """
    import textwrap

    from matplotlib import colormaps
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    from hiab_sim.figure_io import new_figure, png_bytes
    from hiab_sim.study.report.summary import limit_in_words

    v = m.values
    i, j = m.index(m.variables[0]), m.index(m.variables[1])
    feasible = m.grid(v.feasible)
    binding = m.grid(v.binding)
    labels = sorted({v.names[int(k)] for k in binding[~feasible]})
    palette = colormaps["tab10"]
    category = np.full(feasible.shape, np.nan)
    for n, name in enumerate(labels):
        category[(~feasible) & (binding == v.names.index(name))] = n
    what = OBJECTIVE_AXIS.get(m.objective, m.objective.replace("_", " "))
    panels: tuple[tuple[NDArray[np.float64], str], ...] = (
        (v.objective, f"{what} / its value at the study's start [-]"),
        (v.battery_energy / 1e3, f"battery energy [kJ per {per}" + ("]" if len(m.tasks) == 1 else ", weighted]")),
    )
    if not feasible.any():  # nothing to colour: one panel of the limits the cells break
        panels = ((v.objective, "no feasible mounting on this map: the limit each cell breaks"),)
    fig = new_figure((13, 5.6) if len(panels) == 2 else (8.0, 6.2))
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    for ax, (values, title) in zip(axes, panels, strict=True):
        grid = np.ma.masked_where(~feasible, m.grid(values))
        mesh = ax.pcolormesh(m.axes[0], m.axes[1], grid.T, shading="nearest", cmap="viridis")
        if feasible.any():
            fig.colorbar(mesh, ax=ax, label=title)
        if labels:
            cmap = ListedColormap([palette(n % 10) for n in range(len(labels))])
            ax.pcolormesh(
                m.axes[0],
                m.axes[1],
                category.T,
                shading="nearest",
                cmap=cmap,
                alpha=0.35,
                vmin=-0.5,
                vmax=len(labels) - 0.5,
            )
        ax.plot(m.base.xi[i], m.base.xi[j], "*", color="red", mec="k", ms=14,
                label="base (" + m.base.source.split(" (")[0] + ")")  # fmt: skip
        ax.plot(m.start_xi[i], m.start_xi[j], "wo", mec="k", ms=5, label="start")
        lo, hi = m.low[[i, j]], m.up[[i, j]]
        ax.plot([lo[0], hi[0], hi[0], lo[0], lo[0]], [lo[1], lo[1], hi[1], hi[1], lo[1]], "k--", lw=1, label="bounds")
        ax.set_xlabel(variable_words(m.variables[0]))
        ax.set_ylabel(variable_words(m.variables[1]))
        ax.set_title(title, fontsize=10)
    note = infeasible_note(m, with_others=False)  # the legend names every limit by its colour
    if note is not None:
        wrapped = "\n".join(textwrap.fill(part, 58) for part in note.split("\n"))
        for ax in axes:
            ax.text(
                0.5, 0.5, wrapped, transform=ax.transAxes, ha="center", va="center", fontsize=8.5,
                bbox={"boxstyle": "round", "fc": (1.0, 1.0, 1.0, 0.92), "ec": "0.3"},  # white, 92 % opaque
            )  # fmt: skip
    handles, names = axes[0].get_legend_handles_labels()
    handles += [Patch(color=palette(n % 10), alpha=0.35) for n in range(len(labels))]
    names += [f"infeasible: {limit_in_words(name)}" for name in labels]
    fig.legend(handles, names, loc="outside lower center", ncol=len(panels), fontsize=8)
    title = (
        f"Energy map over {m.variables[0]} and {m.variables[1]}; the other decision variables and the trajectory "
        f"at the {m.base.source}"
    )
    if len(panels) == 2:
        title += "\nbattery energy at the battery (shared DC bus, regeneration credited)"
    if len(m.tasks) > 1:
        title += "\nduty mix, objective and energies weighted: " + " + ".join(f"{w:g} x {n}" for n, w in m.tasks)
    fig.suptitle(
        "\n".join(textwrap.fill(part, 180 if len(panels) == 2 else 95) for part in title.split("\n")), fontsize=10
    )
    return png_bytes(fig)

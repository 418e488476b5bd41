"""The answer first of ``energy-map``, ``pareto`` and ``sweep``: the lines a designer reads in ten seconds.

Each function turns what its command computed into a few lines of plain text (also valid
Markdown), in the words of :mod:`hiab_sim.study.report.summary` (limits in words, the energy's
boundary named, the files last). Every number is read from the command's own values; nothing is
recomputed here except the knee of a front (:func:`knee_index`), a choice of which point to name.

* energy map: the best feasible mounting on the map (least study objective) with its battery
  energy against the base design's, the limit binding there, how much of the map is feasible;
* Pareto front: its two end points (the plain optimum, the least criterion the limits allow)
  and its knee, each with the criterion and the objective;
* sweep: the point of least energy at the optimum and the spread of energy and saving over the
  points that finished.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from hiab_sim.percent import change_percent, saving_percent
from hiab_sim.study.report.summary import BATTERY_BOUNDARY, NET_BOUNDARY, before_after, files_line, limit_in_words
from hiab_sim.sweep.energy_map import EnergyMap
from hiab_sim.sweep.map_output import infeasible_note, objective_words
from hiab_sim.sweep.pareto import CRITERIA, CRITERION_AXIS, FrontPoint

#: The study objectives in words (names of :data:`hiab_sim.study.nlp.objectives.OBJECTIVES`).
OBJECTIVE_WORDS = {
    "costf2": "the seed paper's squared-power cost costf2 (a stand-in for energy, not an energy)",
    "battery_energy": f"the battery energy {BATTERY_BOUNDARY}, as the optimiser evaluates it",
}
#: Criteria of a front in words.
CRITERION_WORDS = CRITERION_AXIS


def _short(source: str) -> str:
    """``"start of the study (initial lengths, ...)"`` -> ``"start of the study"``."""
    return source.split(" (")[0]


def map_answer(m: EnergyMap, s: dict[str, Any], title: str, per: str, folder: Path, files: Sequence[str]) -> list[str]:
    """The energy map's answer from the map and its JSON summary ``s`` (:func:`hiab_sim.sweep.map_output.summary`).

    ``per`` names the period the battery energy is counted over (``"cycle"``, or ``"duty period"``
    when the study's duty model adds the rest's hold).
    """
    names = m.variables
    base = s["at_base"]
    base_words = f"base design ({_short(m.base.source)})"
    lines = [f"# {title}: energy map over {names[0]} x {names[1]}, the answer", ""]
    best = s["best_feasible_cell"]
    note = infeasible_note(m)  # where most cells are infeasible: how many are feasible and why the rest are not
    if best is None:  # then the note opens the answer: "No feasible cell of N: ... map ... instead"
        lines.append(_sentence(note) if note is not None else f"No feasible mounting on the map ({s['cells']} cells).")
        lines.append(
            f"Battery energy per {per} {BATTERY_BOUNDARY} at the {base_words}: {base['battery_energy_J'] / 1e3:.3f} kJ."
        )
    else:

        def moves(cell: dict[str, Any]) -> str:
            parts = []
            for name in names:
                value, before = cell["xi_m"][m.index(name)], m.base.xi[m.index(name)]
                parts.append(f"{name} = {value * 1e3:.0f} mm ({(value - before) * 1e3:+.0f})")
            return ", ".join(parts)

        lines.append(
            f"Best feasible mounting on the map (least study objective, {objective_words(m)}): {moves(best)}; "
            f"change from the {base_words} in brackets."
        )
        lines.append(
            f"Battery energy per {per} {BATTERY_BOUNDARY}: "
            + before_after(base["battery_energy_J"], best["battery_energy_J"], ("at the base design", "at the best"))
            + "."
        )
        least = s["least_battery_energy_cell"]
        if least is not None and least["xi_m"] != best["xi_m"]:
            lines.append(
                f"Least battery energy of a feasible mounting on the map: {moves(least)}, "
                f"{least['battery_energy_J'] / 1e3:.3f} kJ "
                f"({_change(least['battery_energy_J'], base['battery_energy_J'])} against the base design)."
            )
        lines.append(
            f"Binding at the best mounting: {limit_in_words(best['binding_constraint'])} "
            f"(scaled margin {best['smallest_margin']:.1e})."
        )
    if best is not None:
        lines.append(f"{s['feasible_cells']} of {s['cells']} cells feasible." if note is None else _sentence(note))
    lines.append(
        f"The other {len(m.design_names) - 2} decision variables and the joint trajectories stay at the {base_words}; "
        f"binding there: {limit_in_words(base['binding_constraint'])}."
    )
    lines += ["", files_line(folder, files)]
    return lines


def _sentence(note: str) -> str:
    """A note of several lines (:func:`hiab_sim.sweep.map_output.infeasible_note`) as one sentence."""
    text = note.replace(";\n", "; ").replace("\n", " ")
    return text[:1].upper() + text[1:] + "."


def knee_index(front: Sequence[FrontPoint]) -> int | None:
    """Index into ``front`` of its knee, or None (fewer than three converged points, or a straight front).

    The knee is the converged point farthest from the chord through the front's two ends, with both
    axes (criterion, objective) scaled to their spans between the ends: the point where trading
    more of one criterion buys least of the other. A choice of definition (the "maximum distance
    to the chord" rule); on a straight front no point stands out.
    """
    ok = [k for k, p in enumerate(front) if p.accepted]
    if len(ok) < 3:
        return None
    c = np.array([front[k].criterion for k in ok])
    f = np.array([front[k].objective for k in ok])
    spans = (c[-1] - c[0], f[-1] - f[0])
    if spans[0] == 0.0 or spans[1] == 0.0:
        return None
    x, y = (c - c[0]) / spans[0], (f - f[0]) / spans[1]
    distance = np.abs(x - y) / math.sqrt(2.0)  # to the line x = y through (0, 0) and (1, 1)
    k = int(np.argmax(distance[1:-1])) + 1
    return ok[k] if distance[k] > 1e-3 else None


def _criterion_text(value: float, criterion: str) -> str:
    unit = CRITERIA[criterion]
    return f"{value / 1e3:.3f} kN" if unit == "N" else f"{value:.4g} {unit}"


def _objective_text(p: FrontPoint, plain: FrontPoint) -> str:
    """The objective of a front point in its unit, its change from the plain optimum, its ratio to the start's."""
    value = (
        f"{p.objective_value / 1e3:.3f} kJ"
        if p.objective_unit == "J"
        else f"{p.objective_value:.6g} {p.objective_unit}"
    )
    change = f"{_change(p.objective, plain.objective)}; " if p is not plain else ""
    return f"{value} ({change}{p.objective:.4f} of the study start's)"


def _change(value: float, reference: float) -> str:
    return f"{change_percent(reference, value):+.2f} %" if reference != 0.0 else "n/a"


def front_answer(
    front: Sequence[FrontPoint],
    criterion: str,
    objective: str,
    title: str,
    folder: Path,
    files: Sequence[str],
    least_design: FrontPoint | None = None,
) -> list[str]:
    """The front's answer: its end points and its knee, the criterion and the objective of each.

    ``least_design``: the least criterion the study's constraints allow and the design reaching it
    (:class:`hiab_sim.sweep.pareto.Front` ``least``), said beside the front when given.
    """
    words = CRITERION_WORDS.get(criterion, criterion.replace("_", " "))
    ok = [p for p in front if p.accepted]
    plain = front[0]
    lines = [f"# {title}: the objective against the {words}, the answer", ""]
    lines.append(f"Objective: {OBJECTIVE_WORDS.get(objective, objective.replace('_', ' '))}.")
    lines.append(f"Front of {len(front)} points, {len(ok)} converged (epsilon-constraint method):")

    def point(label: str, p: FrontPoint) -> str:
        change = f" ({_change(p.criterion, plain.criterion)})" if p is not plain else ""
        value = _criterion_text(p.criterion, criterion)
        return f"- {label}: {words} {value}{change}, objective {_objective_text(p, plain)}"

    lines.append(point(f"plain optimum (no limit on the {words})", plain))
    least = min(ok, key=lambda p: p.criterion) if ok else None
    if least is not None and least is not plain:
        lines.append(point(f"least {words} reached on the front", least))
    if least_design is not None:
        lines.append(
            point(
                f"least {words} the study's limits allow (minimised alone; the front ends just above it)", least_design
            )
        )
    knee = knee_index(front)
    if knee is None:
        lines.append("- knee: none (fewer than three converged points, or the front is straight)")
    else:
        lines.append(point("knee (farthest from the line through the ends)", front[knee]))
        knee_point = front[knee]
        names = knee_point.design_names or tuple(f"xi_{k}" for k in range(len(knee_point.xi)))
        lines.append(
            "  decision variables at the knee [mm]: "
            + ", ".join(f"{n} {v * 1e3:.0f}" for n, v in zip(names, knee_point.xi, strict=True))
        )
    failed = len(front) - len(ok)
    if failed:
        lines.append(f"{failed} point(s) did not converge (listed below); they are not on the front.")
    lines += ["", files_line(folder, files)]
    return lines


def energy_columns(frame: pd.DataFrame, ok: pd.Series) -> tuple[str, str, str]:
    """(optimum's column, start's column, boundary in words): the battery's where every finished point has it."""
    column = "opt_battery_energy_J"
    if column in frame and ok.any() and np.isfinite(frame.loc[ok, column].to_numpy(dtype=float)).all():
        return column, "start_battery_energy_J", BATTERY_BOUNDARY
    return "opt_net_energy_J", "start_net_energy_J", NET_BOUNDARY


def sweep_answer(
    frame: pd.DataFrame, axes: Sequence[str], title: str, folder: Path, files: Sequence[str], per: str = "cycle"
) -> list[str]:
    """The sweep's answer: the point of least energy at its optimum and the spread over the finished points.

    ``per`` names the period the battery energy covers (``"cycle"``, or ``"duty period"`` when the
    study's duty model adds the rest's hold); the net electrical energy is always per cycle.
    """
    ok = frame["status"] == "ok"
    lines = [f"# {title}: sweep of {len(frame)} points over {', '.join(axes)}, the answer", ""]
    if not ok.any():
        lines.append(f"No point finished: all {len(frame)} failed (messages below).")
        lines += ["", files_line(folder, files)]
        return lines
    column, start_column, boundary = energy_columns(frame, ok)
    done = frame[ok]
    best = done.loc[done[column].astype(float).idxmin()]
    values = ", ".join(f"{a} = {best[a]}" for a in axes)
    lines.append(f"Least energy at the optimum: point {best['key']} ({values}).")
    period = per if boundary == BATTERY_BOUNDARY else "cycle"
    lines.append(
        f"Energy per {period} {boundary}: "
        + before_after(float(best[start_column]), float(best[column]), ("at its start", "at its optimum"))
        + "."
    )
    energy = done[column].astype(float) / 1e3
    saving = saving_percent(done[start_column].astype(float), done[column].astype(float))
    lines.append(
        f"Spread over the {int(ok.sum())} finished point(s), at the same boundary: energy at the optimum "
        f"{energy.min():.3f} .. {energy.max():.3f} kJ; saved by the optimisation {saving.min():.2f} .. "
        f"{saving.max():.2f} %."
    )
    failed = int((~ok).sum())
    lines.append(f"{failed} of {len(frame)} points failed (messages below)." if failed else "No point failed.")
    lines += ["", files_line(folder, files)]
    return lines

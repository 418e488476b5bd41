"""The answer first: the short summary a designer reads in ten seconds, built from the typed result.

``hiab-sim optimize`` prints it last and writes the same text to ``summary.md`` in the run folder.
It says what to build (the buildable design, each link length and its move from the initial
design in mm), the energy per cycle before and after at the boundary the study reports (the
battery on the shared DC bus when the result has an energy section, else the motors' net
electrical energy), the limits that bind at the optimum (the active constraints of largest
multiplier, in words) and where the files are. Every number is read from the result; nothing is
recomputed here.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import fields
from pathlib import Path

from hiab_sim.crane.description import LinkLengths
from hiab_sim.machine.design import MachineDesign
from hiab_sim.percent import change_percent, saving_percent
from hiab_sim.results.design_values import DesignValues
from hiab_sim.results.schema import Result

#: File name of the summary inside a run folder.
SUMMARY_FILE = "summary.md"
#: Binding limits named in the summary (largest cost per unit of relaxation first).
BINDING_SHOWN = 3
#: Relative objective gain above which the cross-evaluation's re-driven mix design flags the optimum's trajectories
#: as a local optimum (the spread of the NLP's local optima between starts is ~1e-5 on the test studies).
TRAJECTORY_GAIN_SHOWN = 1e-4
#: The boundary of the battery energy in words: what every answer-first summary states its energy at.
BATTERY_BOUNDARY = "at the battery (shared DC bus, regeneration credited)"
#: The boundary shown instead when a result has no battery model.
NET_BOUNDARY = "net electrical energy of the motors (regeneration credited; no battery model in this study)"

#: Link-length fields of one chain in words (see :class:`hiab_sim.crane.description.ChainLengths`).
LENGTH_WORDS = {
    "L": "base pivot to boom hinge",
    "Lc0": "piston offset in the barrel",
    "Lc": "rod length",
}

_ENVELOPE_WORDS = {"peak_torque": "motor peak torque", "rated_speed": "motor rated speed", "voltage": "drive voltage"}
_STROKE_WORDS = {
    "x >= 0": "cylinder fully retracted",
    "x <= Lc": "rod fully out of the barrel",
    "x <= stroke": "end of stroke",
}
_TRACKING = re.compile(r"^tracking\.(\w+)\.(\S+)")
#: The tool point's tracked coordinates in words; any other tracked coordinate is a joint of the machine.
_COORDINATE_WORDS = {"x_tcp": "TCP x (horizontal)", "y_tcp": "TCP y (vertical)"}
_BOUND = re.compile(r"^bound (\w+)\.(\w+) (low|up) = (\S+) m$")
#: A duty mix's row of one task: ``<task>: <row>``.
_TASK_ROW = re.compile(r"^([^:]+): (.+)$")


def limit_with_row(name: str) -> str:
    """A constraint row in a designer's words, its name in ``result.json`` beside it where they differ."""
    words = limit_in_words(name)
    return name if words == name else f"{words} ({name})"


def limit_in_words(name: str, detail: bool = True) -> str:
    """A constraint row name of the NLP (``envelope.lift.peak_torque``, ``bound tilt.L up = 1.3 m``) in words.

    Names the sensitivity section groups over samples; an unknown pattern keeps its name with
    underscores as spaces. ``detail`` False drops the coordinate of a tracking band (one phrase
    for the band, as the summary names it). A duty mix's row of one task (``digging: stroke.boom...``,
    :meth:`hiab_sim.study.nlp.problem.StudyProblem.row_name`) keeps its task in front of the words.
    """
    task = _TASK_ROW.match(name)
    if task:
        return f"{task.group(1)}: {limit_in_words(task.group(2), detail)}"
    match = _BOUND.match(name)
    if match:
        chain, field, side, value = match.groups()
        words = LENGTH_WORDS.get(field, field)
        return f"{chain} {words} at its {'lower' if side == 'low' else 'upper'} bound ({float(value) * 1e3:.0f} mm)"
    match = _TRACKING.match(name)
    if match:
        band = f"TCP tracking band ({match.group(1)})"
        if not detail:
            return band
        if match.group(2) in _COORDINATE_WORDS:
            return f"{band}, {_COORDINATE_WORDS[match.group(2)]}"
        return f"tracking band ({match.group(1)}), joint {match.group(2)}"
    block, _, rest = name.partition(".")
    if block == "envelope":
        actuator, _, limit = rest.partition(".")
        return f"{actuator} {_ENVELOPE_WORDS.get(limit, limit.replace('_', ' '))}"
    if block in ("stroke", "working_range", "buildable_range"):
        chain, _, row = rest.partition(".")
        end = ""
        for side in ("low", "up"):
            suffix = f" at the {side} end"
            if row.endswith(suffix):
                row, end = (
                    row[: -len(suffix)],
                    f" at the {'lower' if side == 'low' else 'upper'} end of the joint range",
                )
        where = {"stroke": "", "working_range": " over the working range", "buildable_range": " over the build range"}
        return f"{chain} {_STROKE_WORDS.get(row, row)}{where[block]}{end}"
    if block == "joint_velocity":
        return f"joint speed limit ({rest.split(' ')[0]})"
    if block == "mounting":
        return f"mounting space ({rest.replace('_', ' ')})"
    return name.replace("_", " ")


def _design_lines(built: DesignValues, initial: DesignValues, tolerance_mm: float | None) -> list[str]:
    rounding = f", rounded to {tolerance_mm:g} mm" if tolerance_mm is not None else ""
    lines = [f"What to build (link lengths in mm, change from the initial design in brackets{rounding}):"]
    if isinstance(built, MachineDesign) or isinstance(initial, MachineDesign):
        old = dict(zip(initial.names, initial.values, strict=True)) if isinstance(initial, MachineDesign) else {}
        assert isinstance(built, MachineDesign)
        for name, value in zip(built.names, built.values, strict=True):
            lines.append(f"- {name}: {value * 1e3:.0f} ({(value - old.get(name, value)) * 1e3:+.0f})")
        return lines
    for chain in (f.name for f in fields(LinkLengths)):
        new, old = getattr(built, chain), getattr(initial, chain)
        parts = []
        for field, words in LENGTH_WORDS.items():
            value, before = getattr(new, field), getattr(old, field)
            parts.append(f"{words} {value * 1e3:.0f} ({(value - before) * 1e3:+.0f})")
        lines.append(f"- {chain} chain: " + ", ".join(parts))
    return lines


def energy_line(r: Result) -> str:
    """The energy before/after, named with its boundary and the period it covers.

    With the study's duty model the battery energy covers a duty period (the cycle and the rest that
    follows it); a study of several tasks reports the tasks' weighted sum (the study's weights, e.g.
    cycles per hour: then J per hour), a study of one task of weight w != 1 w times its energy and the
    task's own per cycle beside it [kJ in the line].
    """
    reports = [t.energy for t in r.tasks] if r.tasks else [r.energy]
    with_duty = any(e is not None and e.optimal.duty is not None for e in reports)
    period = "duty period (cycle and rest)" if r.energy is not None and with_duty else "cycle"
    if r.energy is not None:
        e = r.energy
        before, after = e.initial.battery_energy_J, e.optimal.battery_energy_J
        where = BATTERY_BOUNDARY
    else:
        before, after = r.initial.net_electrical_energy_J, r.optimal.net_electrical_energy_J
        where = NET_BOUNDARY
    if not r.tasks:
        return f"Energy per {period} {where}: {before_after(before, after)}."
    if len(r.tasks) > 1:
        head = f"Energy, the tasks' weighted sum of their energies per {period} (weights in cycles per hour: per hour)"
        return f"{head} {where}: {before_after(before, after)}."
    task = r.tasks[0]
    if task.energy is not None and r.energy is not None:
        one = (task.energy.initial.battery_energy_J, task.energy.optimal.battery_energy_J)
    else:
        one = (task.initial.net_electrical_energy_J, task.optimal.net_electrical_energy_J)
    head = (
        f"Energy, weight {task.weight:g} x the energy per {period} of task '{task.name}' "
        "(the weight in cycles per hour: per hour)"
    )
    return f"{head} {where}: {before_after(before, after)}; per {period}: {before_after(*one)}."


def before_after(before: float, after: float, names: tuple[str, str] = ("before", "after")) -> str:
    """``"15.670 kJ before, 15.230 kJ after (-2.81 %)"`` from two energies [J] (the change relative to ``before``).

    The change is signed as the energy moves (less energy: negative), also when ``before`` is negative
    (a cycle that regenerates more than it draws).
    """
    change = f" ({change_percent(before, after):+.2f} %)" if before != 0.0 else ""
    return f"{before / 1e3:.3f} kJ {names[0]}, {after / 1e3:.3f} kJ {names[1]}{change}"


def files_line(folder: Path, files: Sequence[str]) -> str:
    """The summary's last line: where the files are."""
    return f"Files in {folder}: {', '.join(files)}."


def _trajectory_line(r: Result) -> str | None:
    """A line when the cross-evaluation drives the optimum's design cheaper than the optimiser's own trajectories.

    The cross-evaluation re-optimises the mix design's trajectories at its Xi from the inverse-kinematics
    fit as well as from the optimiser's own (:mod:`hiab_sim.study.analysis.cross_evaluation`); a
    weighted objective lower by more than :data:`TRAJECTORY_GAIN_SHOWN` means the optimum is local in its
    trajectories, and so possibly in its design.
    """
    c, s = r.cross_evaluation, r.sensitivity
    if c is None or s is None or c.mix_objective_value is None or s.objective_value == 0.0:
        return None
    driven = c.mix_objective_value[-1]
    if driven is None:
        return None
    gain = saving_percent(s.objective_value, driven)
    if gain <= 100.0 * TRAJECTORY_GAIN_SHOWN:
        return None
    return (
        f"Local optimum: driven from the inverse-kinematics fit (the cross-evaluation), this design costs {gain:.2g} % "
        f"less ({s.objective}, weighted over the tasks) than with the optimiser's own trajectories, which the "
        "numbers above are; other starts (--starts) may find a better design."
    )


def _moved_start(r: Result) -> str | None:
    """What the feasibility phase did to the study's own start (start 0, the result's), or None where it was feasible.

    The result's ``initial`` design is the moved start, so the changes above and the saving below are
    measured from it, not from the study file's ``initial_lengths``: said here, where they are read.
    """
    phase = next((f for f in r.feasibility or () if f.start == 0), None)
    if phase is None:
        return None
    return (
        f"  The study's initial design violated a limit ({limit_in_words(phase.initial_worst, detail=False)}); "
        f"before optimising, the feasibility phase moved it: {'; '.join(phase.changes)}. The changes above and "
        "the saving below are measured from the moved start."
    )


def _thermal_line(r: Result) -> str | None:
    """A line when the optimum's motors exceed their thermal limits in a study that does not hold them.

    Without ``duty:`` the study has no thermal rows (:mod:`hiab_sim.study.constraints.thermal_rows`), yet the
    result reports each motor's RMS torque and winding temperature over back-to-back cycles; "all limits hold"
    must not read as covering them.
    """
    reports = [(f"{t.name}: ", t.energy) for t in r.tasks] if r.tasks else [("", r.energy)]
    over = []
    for task, e in reports:
        if e is None or e.optimal.duty is not None or e.optimal.thermal is None:
            continue
        for name, th in e.optimal.thermal.items():
            if th.torque_margin < 0.0 or th.temperature_margin_K < 0.0:
                over.append(
                    f"{task}{name} winding {th.peak_winding_temperature_C:.0f} degC (limit "
                    f"{th.max_winding_temperature_C:.0f}), RMS torque {th.rms_torque_Nm:.3g} of "
                    f"{th.continuous_torque_Nm:.3g} N m"
                )
    if not over:
        return None
    return (
        "Thermal limits exceeded over back-to-back cycles, and not held by this study (it gives no duty:): "
        + "; ".join(over)
        + ". Give the duty (rest, hold) to hold them."
    )


def binding_line(r: Result) -> str:
    """The limits that bind at the optimum, in words, largest multiplier first.

    The multipliers are gains in the study's objective (``sensitivity.objective``: the battery energy
    [J], or the seed's costf2 [W^2 s], a squared power and not an energy), so the line names it.
    """
    s = r.sensitivity
    binding: list[str] = []
    for m in () if s is None else s.multipliers:
        words = limit_in_words(m.constraint, detail=False)
        if words not in binding and len(binding) < BINDING_SHOWN:
            binding.append(words)
    if s is None or not binding:
        return "Binding limits at the optimum: none reported (no sensitivity section)."
    gain = "energy gain" if s.objective == "battery_energy" else f"gain in {s.objective} [{s.objective_unit}]"
    return f"Binding limits at the optimum (largest {gain} per unit relaxed first): " + "; ".join(binding) + "."


def check_line(r: Result) -> str:
    """Whether every limit holds on the fine-grid re-check with the other dynamics model (scaled violation)."""
    violation = r.recheck.max_violation_scaled
    return f"Checked on a {r.recheck.grid_points}-point grid with the other dynamics model: " + (
        "all limits hold." if violation <= 1e-6 else f"largest violation {violation:.1e} (scaled)."
    )


def summary_lines(r: Result, folder: Path, files: Sequence[str] = ()) -> list[str]:
    """The summary as lines of Markdown (also readable as plain console text)."""
    built = r.buildable.lengths if r.buildable is not None else r.optimal.lengths
    tolerance = r.buildable.tolerance_m * 1e3 if r.buildable is not None else None
    lines = [f"# {r.name}: the answer", ""]
    lines += _design_lines(built, r.initial.lengths, tolerance)
    if r.buildable is None:
        lines.append("  (the optimum itself: this study has no buildable-design check)")
    moved = _moved_start(r)
    if moved is not None:
        lines.append(moved)
    lines += ["", energy_line(r)]
    lines.append(binding_line(r))
    ms = r.multistart
    if len(ms.starts) > 1:
        failed = f", {len(ms.failed_starts)} failed" if ms.failed_starts else ""
        agree = "the same optimum" if ms.same_optimum else f"{len(ms.distinct_optima)} distinct local optima"
        values = [d.objective_value for d in ms.distinct_optima if d.objective_value is not None]
        if not ms.same_optimum and len(values) == len(ms.distinct_optima) and min(values) != 0.0:
            spread = change_percent(min(values), max(values))
            reported = change_percent(min(values), values[0])  # the result is start 0's optimum
            where = "the lowest" if reported == 0.0 else f"{reported:.2g} % above the lowest"
            agree += f" (their {ms.objective} within {spread:.2g} % of the lowest; the result is start 0's, {where})"
        lines.append(f"Starts: {ms.converged_starts} of {len(ms.starts)} converged, to {agree}{failed}.")
    for extra in (_trajectory_line(r), _thermal_line(r)):
        if extra is not None:
            lines.append(extra)
    lines.append(check_line(r))
    if r.buildable is not None:
        lines.append(f"Model of the buildable design: {r.buildable.mjcf_command}")
    lines += ["", files_line(folder, files or ("result.json", "trajectory.npz"))]
    return lines


def summary_text(r: Result, folder: Path, files: Sequence[str] = ()) -> str:
    """The summary as one text (what ``summary.md`` holds and the console prints)."""
    return "\n".join(summary_lines(r, folder, files)) + "\n"

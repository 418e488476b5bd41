"""The report's first half: the question and the machine, the design to build and its pivot moves, the energies."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.design_report.page import esc, figure, num, paragraph, section, table
from hiab_sim.machine.description import Machine
from hiab_sim.percent import change_percent
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.results.schema import Result
from hiab_sim.study.report.summary import binding_line, check_line, energy_line


def _lengths_text(lengths: LinkLengths, crane: Crane) -> str:
    parts = []
    for chain in crane.chains:
        xi = getattr(lengths, chain.name)
        parts.append(f"{chain.name} L / Lc0 / Lc = {xi.L:.3f} / {xi.Lc0:.3f} / {xi.Lc:.3f} m")
    return "; ".join(parts)


def built_lengths(result: Result) -> LinkLengths:
    """The design to build: the rounded (buildable) design when the result has one, else the optimum."""
    return crane_lengths(result.optimal.lengths if result.buildable is None else result.buildable.lengths)


#: A machine file's decision-variable kinds in words (:mod:`hiab_sim.machine.design`).
KIND_WORDS = {
    "hinge_distance": "pivot distance from the chain's hinge (the seed's L)",
    "pivot_x": "pivot x in its link frame",
    "pivot_y": "pivot y in its link frame",
    "piston_offset": "piston offset Lc0",
    "rod_length": "rod length Lc",
    "retracted_length": "retracted length x0 = Lc0 + Lc",
}


def _variables_text(machine: Crane | Machine) -> str:
    if isinstance(machine, Crane):
        return "per chain: base pivot distance L, piston offset Lc0, rod length Lc [m]"
    return ", ".join(f"{v.key} ({KIND_WORDS.get(v.kind, v.kind)})" for v in machine.decision_variables) + " [m]"


def question(result: Result, machine: Crane | Machine) -> str:
    """What was asked, of which machine (a crane file's or a machine file's), for which work."""
    tasks = (
        f"{len(result.tasks)} task{'s' if len(result.tasks) > 1 else ''} (a duty mix: "
        + ", ".join(f"{t.name} x {t.weight:g}" for t in result.tasks)
        + ")"
        if result.tasks
        else f"the study's reference motion ({result.settings.fine_grid_points} fine-grid samples)"
    )
    names = {
        "costf2": "the seed paper's cost costf2 (squared summed electrical power)",
        "battery_energy": "the battery's energy",
    }
    objective = (
        names["costf2"] if result.energy is None else names.get(result.energy.objective, result.energy.objective)
    )
    rows = [
        ("study", result.name),
        ("machine", f"{machine.name} ({machine.source if isinstance(machine, Crane) else result.crane})"),
        ("work", tasks),
        ("payload", f"{result.settings.payload_kg:g} kg"),
        ("objective", objective),
        ("decision variables", _variables_text(machine)),
    ]
    duty = duty_words(result)
    if duty is not None:
        rows.append(("duty", duty))
    return section(
        "The question",
        paragraph(
            "Where should the electromechanical linear actuators be mounted so that the machine does this work "
            "on the least energy, within its actuators' envelope, strokes, joint ranges and thermal limits?"
        ),
        table(("item", "value"), rows),
    )


def _buildable_text(result: Result) -> str:
    if result.buildable is None:
        return ""
    b = result.buildable
    return (
        f" Rounded to the {1e3 * b.tolerance_m:g} mm manufacturing tolerance with a {1e3 * b.stroke_margin_m:g} mm "
        f"stroke margin; every design within ±{1e3 * b.tolerance_m:g} mm stays feasible (worst margin "
        f"{1e3 * b.tolerance_check.margin:.3f} mm) and its net energy differs from the optimum's by "
        f"{b.net_energy_change_vs_optimum_J + 0.0:+.1f} J. Export: {b.mjcf_command}"
    )


def duty_words(result: Result) -> str | None:
    """The study's duty: a duty mix's per task (``result.json`` ``tasks[k].energy.duty``); None without energies."""
    per_task = [f"{t.name}: {t.energy.duty}" for t in result.tasks or () if t.energy is not None]
    if per_task:
        return "; ".join(per_task)
    return None if result.energy is None else result.energy.duty


def _verdict(result: Result) -> str:
    """The answer's second half, as the summary states it: battery energy saved, binding limits, all limits hold."""
    return paragraph(" ".join((energy_line(result), binding_line(result), check_line(result))))


def machine_design(result: Result, machine: Machine, folder: Path) -> str:
    """A machine file's design to build: each decision variable and each pivot it moves, in the link's frame."""
    chosen = result.optimal.lengths if result.buildable is None else result.buildable.lengths
    before_values, after_values = result.initial.lengths.as_array(), chosen.as_array()
    rows = [
        (v.key, KIND_WORDS.get(v.kind, v.kind), f"{a:.4f} → {b:.4f}", f"{1e3 * (b - a):+.1f} mm")
        for v, a, b in zip(machine.decision_variables, before_values, after_values, strict=True)
    ]
    before, after = (
        machine.with_design(before_values, check_bounds=False),
        machine.with_design(after_values, check_bounds=False),
    )
    moves = []
    for old, new in zip(before.chains, after.chains, strict=True):
        for p, q in zip(old.pivots, new.pivots, strict=True):
            delta = 1e3 * (np.asarray(q.position, dtype=float) - np.asarray(p.position, dtype=float))
            if np.any(np.abs(delta) > 1e-9):
                moves.append((f"{old.name}.{p.role}", p.link, f"Δx {delta[0]:+.1f}, Δy {delta[1]:+.1f} mm"))
    text = (
        "Build "
        + "; ".join(f"{v.key} = {b:.4f} m" for v, b in zip(machine.decision_variables, after_values, strict=True))
        + "."
    )
    return section(
        "The answer: the design to build",
        f'<div class="answer">{paragraph(text + _buildable_text(result))}{_verdict(result)}</div>',
        table(("variable", "meaning", "initial → design [m]", "change"), rows),
        table(("pivot", "on link", "move in the link's frame"), moves) if moves else "",
    )


def design(result: Result, crane: Crane, folder: Path) -> str:
    """The design to build, the dimensioned pivot moves and the structure drawing."""
    build = built_lengths(result)
    initial = result.initial.lengths
    rows = []
    for chain in crane.chains:
        before, after = getattr(initial, chain.name), getattr(build, chain.name)
        move = 1e3 * (chain.base_pivot(after) - chain.base_pivot(before))
        rows.append(
            (
                chain.name,
                f"{before.L:.3f} → {after.L:.3f}",
                f"{1e3 * (after.L - before.L):+.0f} mm along the cylinder axis "
                f"(Δx {move[0]:+.0f}, Δy {move[1]:+.0f} mm "
                f"in {chain.parent})",
                f"{before.Lc0 + before.Lc:.3f} → {after.Lc0 + after.Lc:.3f}",
                f"{before.Lc0:.3f} / {before.Lc:.3f} → {after.Lc0:.3f} / {after.Lc:.3f}",
            )
        )
    text = f"Build {_lengths_text(build, crane)}." + _buildable_text(result)
    return section(
        "The answer: the design to build",
        f'<div class="answer">{paragraph(text)}{_verdict(result)}</div>',
        table(
            ("chain", "L [m] (base pivot to boom hinge)", "base pivot move", "retracted length x0 [m]", "Lc0 / Lc [m]"),
            rows,
        ),
        figure(folder / "structure_initial_vs_optimal.png", "Initial (built) and optimal structure, pivot moves"),
    )


def energies(result: Result, folder: Path) -> str:
    """Every energy with the boundary it is drawn at, initial against the design."""
    i, o = result.initial, result.optimal
    saved = result.improvement.net_energy_saved_percent
    rows: list[tuple[str, str, str, str, str]] = []
    if result.energy is not None:
        e = result.energy
        di, do = e.initial.duty, e.optimal.duty
        boundary = "at the battery (inverters, shared DC bus, battery efficiencies)"
        if result.tasks:
            battery = "battery energy, the tasks' weighted sum"
        else:
            battery = "battery energy per cycle" if do is None else "battery energy per duty period (cycle and rest)"
        rows.append(
            (
                battery,
                boundary,
                num(e.initial.battery_energy_J, ".1f", "J"),
                num(e.optimal.battery_energy_J, ".1f", "J"),
                f"{-e.battery_energy_saved_percent:+.2f} %",
            )
        )
        if di is not None and do is not None:
            rows.append(
                (
                    "battery energy of the cycle alone (no rest)",
                    boundary,
                    num(di.cycle_battery_energy_J, ".1f", "J"),
                    num(do.cycle_battery_energy_J, ".1f", "J"),
                    f"{change_percent(di.cycle_battery_energy_J, do.cycle_battery_energy_J):+.2f} %",
                )
            )
    rows.append(
        (
            "net electrical energy",
            "motor terminals, summed over the drives (regeneration credited)",
            num(i.net_electrical_energy_J, ".1f", "J"),
            num(o.net_electrical_energy_J, ".1f", "J"),
            f"{-saved:+.2f} %",
        )
    )
    if result.buildable is not None:  # the answer builds the rounded design; its energy is not the optimum's
        b = result.buildable
        rows.append(
            (
                "net electrical energy of the rounded design to build",
                f"motor terminals, the optimal trajectory at the rounded lengths ({b.recheck_id_path} ID path)",
                num(i.net_electrical_energy_J, ".1f", "J"),
                num(b.net_electrical_energy_J, ".1f", "J"),
                f"{change_percent(i.net_electrical_energy_J, b.net_electrical_energy_J):+.2f} %",
            )
        )
    rows += [
        (
            "energy drawn, summed power",
            "motor terminals, positive part of the summed power",
            num(i.drawn_energy_summed_drives_J, ".1f", "J"),
            num(o.drawn_energy_summed_drives_J, ".1f", "J"),
            "",
        ),
        (
            "copper loss",
            "stator windings",
            num(i.energy_breakdown_J.copper, ".1f", "J"),
            num(o.energy_breakdown_J.copper, ".1f", "J"),
            "",
        ),
        (
            "costf2 (the seed's cost)",
            "squared summed power, not an energy",
            num(i.cost_W2s, ".4g", "W² s"),
            num(o.cost_W2s, ".4g", "W² s"),
            "",
        ),
    ]
    d = result.improvement.decomposition
    note = ""
    if d.from_lengths_J is not None and d.from_trajectory_J is not None:
        interaction = "" if d.interaction_J is None else f" and {d.interaction_J:+.1f} J from their interaction"
        note = paragraph(
            f"Of the {result.improvement.net_energy_saved_J:.1f} J net energy saved, {d.from_lengths_J:.1f} J come "
            f"from the lengths alone (optimal lengths on the initial trajectory), {d.from_trajectory_J:.1f} J from "
            f"re-shaping the trajectory within the tracking bands{interaction}.",
            "note",
        )
    mix = ""
    if result.tasks:
        weights = ", ".join(f"{t.name} x {t.weight:g}" for t in result.tasks)
        mix = paragraph(
            f"A duty mix: every energy on this page but the duty-mix section's is the tasks' weighted sum ({weights}) "
            "of each task's energy per cycle, or per duty period at the battery where the task has a duty; with the "
            "weights in cycles per hour, J per hour. Each task's own energies are in the duty-mix section.",
            "note",
        )
    return section(
        "Energies and their boundaries",
        mix,
        table(("quantity", "boundary", "initial", "optimum", "change"), rows, numeric=(2, 3, 4)),
        note,
        figure(folder / "energy_breakdown.png", "Energy by power flow, initial and optimal"),
    )


def actuator_table(result: Result) -> str:
    """Peaks and envelope margins per actuator at the optimum."""
    rows = [
        (
            name,
            num(a.peak_force_N / 1e3, ".1f", "kN"),
            num(a.peak_velocity_m_per_s, ".3f", "m/s"),
            num(a.peak_electrical_power_W / 1e3, ".2f", "kW"),
            num(a.min_envelope_margin, ".3f"),
            num(a.net_energy_J, ".1f", "J"),
        )
        for name, a in result.optimal.actuators.items()
    ]
    net = "net energy, the tasks' weighted sum" if result.tasks else "net energy"
    return table(
        ("actuator", "peak force", "peak speed", "peak power", "min envelope margin (>= 0)", net),
        rows,
        numeric=(1, 2, 3, 4, 5),
    )


def esc_list(items: list[str]) -> str:
    """An HTML list of escaped items."""
    return "<ul>" + "".join(f"<li>{esc(i)}</li>" for i in items) + "</ul>" if items else ""

"""The report's second half: constraints and margins, thermal state, sensitivities, hydraulics, closed loop, mix."""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TypeVar

from hiab_sim.design_report.answer import actuator_table, duty_words
from hiab_sim.design_report.page import figure, num, paragraph, section, table
from hiab_sim.design_report.simulation_table import COLUMNS, NUMERIC, run_groups, table_header, table_rows
from hiab_sim.results.energy_sections import HydraulicBaseline
from hiab_sim.results.schema import Result
from hiab_sim.structure.summary import BucklingSummary
from hiab_sim.study.report.summary import limit_with_row

T = TypeVar("T")
#: KKT fit residual above which the report calls the multipliers rough: a choice, 1 % of the gradient left
#: unexplained (the single-task studies fit to 1e-6 .. 3e-3; a duty mix to 1.5e-1 on exact_duty_mix).
ROUGH_FIT = 1e-2


def constraints(result: Result) -> str:
    """Feasibility at the optimum: solver, worst row, re-check with the other path, buildable checks, envelope."""
    o, rc, sol = result.optimal, result.recheck, result.solver
    rows = [
        ("solver", f"{sol.method}: {sol.message}, {sol.iterations} iterations, {sol.wall_time_s:.1f} s"),
        ("largest violation (optimiser's grid, scaled)", f"{sol.max_violation_scaled:.2e}"),
        (
            f"re-check: {rc.grid_points} points, {rc.id_path} inverse dynamics",
            f"largest violation {rc.max_violation_scaled:.2e}; TCP error {1e3 * rc.tracking_error.position_m:.3f} mm; "
            f"force difference between the two paths {rc.force_difference_between_paths_N:.2e} N",
        ),
        (
            "least margin at the optimum",
            f"{limit_with_row(o.worst_constraint.name)}: {o.worst_constraint.scaled_margin:.3e} (scaled)",
        ),
    ]
    b = result.buildable
    if b is not None:
        for label, check in (
            ("machine check", b.crane_check),
            ("tolerance box", b.tolerance_check),
            ("rounded design re-check", b.recheck),
        ):
            rows.append(
                (label, f"{'passed' if check.passed else 'FAILED'}: {check.worst} ({check.margin:.3g} {check.unit})")
            )
    ms = result.multistart
    if len(ms.starts) > 1:
        rows.append(("starts", f"{ms.converged_starts} converged; same optimum: {ms.same_optimum}"))
    order = "" if b is None else f"±{1e3 * b.tolerance_m:g} mm on each of {', '.join(b.lengths.names)}, in order"
    corners = paragraph(f"A corner of the tolerance box is named by its signs: {order}.", "note") if order else ""
    return section(
        "Constraints and margins at the optimum",
        table(("check", "value"), rows),
        corners,
        actuator_table(result),
    )


def thermal(result: Result) -> str:
    """Each motor's RMS torque and winding temperature over the duty, against its limits (a duty mix: per task)."""
    tasks = [(t.name, t.energy) for t in result.tasks or () if t.energy is not None]
    studies = tasks if result.tasks else [("", result.energy)]
    rows = [
        (
            *((task,) if result.tasks else ()),
            name,
            f"{t.rms_torque_Nm:.2f} / {t.continuous_torque_Nm:.1f} N m",
            f"{t.peak_winding_temperature_C:.1f} / {t.max_winding_temperature_C:.0f} °C",
            f"{100 * t.torque_margin:.0f} %",
        )
        for task, e in studies
        if e is not None and e.optimal.thermal is not None
        for name, t in e.optimal.thermal.items()
    ]
    if not rows:
        return ""
    duty = duty_words(result)
    header = ("motor", "RMS torque / continuous", "winding peak / maximum", "torque margin")
    first = 1 if result.tasks else 0
    return section(
        "Thermal state",
        paragraph(
            f"Duty: {duty}. RMS motor torque against the continuous torque, periodic steady-state winding "
            "temperature against its maximum, at the optimum"
            + (", per task (each task's own cycle and duty)." if result.tasks else ".")
        ),
        table(
            (("task",) if result.tasks else ()) + header,
            rows,
            numeric=tuple(range(first + 1, first + 4)),
        ),
    )


def sensitivities(result: Result, folder: Path) -> str:
    """KKT multipliers: what relaxing each active limit is worth."""
    s = result.sensitivity
    if s is None or not s.multipliers:
        return ""
    rows = [
        (
            limit_with_row(m.constraint),
            m.unit,
            f"{m.percent_per_unit:.4f} %",
            f"{m.objective_decrease_per_unit:.4g} {s.objective_unit}",
        )
        for m in sorted(s.multipliers, key=lambda m: -m.percent_per_unit)
    ]
    return section(
        "Sensitivities",
        paragraph(
            f"Decrease of the objective ({s.objective}, {s.objective_value:.6g} {s.objective_unit} at the optimum on "
            "the optimiser's collocation grid, not the fine grid of the energies above) "
            f"per unit each active limit is relaxed (KKT residual {s.kkt_residual:.1e}); a slope, "
            "not a promise for large moves."
            + (
                f" The multipliers leave {100 * s.kkt_residual:.0f} % of the objective's gradient unexplained "
                f"(|grad f - J_A^T lambda| / |grad f| > {ROUGH_FIT:g}): read them as rough."
                if s.kkt_residual > ROUGH_FIT
                else ""
            ),
            "note",
        ),
        table(("active constraint", "per", "% of the objective", "objective decrease per unit"), rows, numeric=(2, 3)),
        figure(folder / "sensitivity.png", "KKT multipliers of the active constraints"),
    )


def _at_battery_rows(h: HydraulicBaseline) -> tuple[list[str], list[tuple[str, ...]]] | None:
    """Variants and rows of the comparison at the battery over the cycle, None where the result has none."""
    designs = (("initial", h.initial), ("optimal", h.optimal))
    if any(d.at_battery is None or d.emla_cycle_battery_energy_J is None for _, d in designs):
        return None
    variants = list(h.optimal.at_battery or {})
    rows = []
    for design, d in designs:
        at = d.at_battery or {}
        cells = [
            f"{at[v].cycle_battery_energy_J / 1e3:.2f} kJ ({at[v].emla_saving_percent:.1f} %)" if v in at else "–"
            for v in variants
        ]
        rows.append((design, num((d.emla_cycle_battery_energy_J or 0.0) / 1e3, ".2f", "kJ"), *cells))
    return variants, rows


def hydraulics(result: Result, folder: Path) -> str:
    """The hydraulic cylinders the EMLAs replace, for the same motion and loads.

    Where the result has it, every variant at the battery over the cycle against the EMLAs' battery energy
    of the same cycle [kJ]: one boundary, one period. Below it, the pump motors' electric input of the
    valve-controlled supplies [kJ] and their system efficiency.
    """
    h = result.hydraulic_baseline
    if h is None:
        return ""
    parts = []
    battery = _at_battery_rows(h)
    if battery is not None:
        variants, rows = battery
        parts += [
            paragraph(
                "At the battery, over the cycle (the rest of a duty period excluded): each hydraulic variant with its "
                "pump, the pump's motor and inverter, valves and leakage, against the EMLAs' battery energy of the "
                "same cycle; in brackets the EMLAs' saving against it."
            ),
            table(
                ("design", "EMLA", *(v.replace("_", " ") for v in variants)),
                rows,
                numeric=tuple(range(1, len(variants) + 2)),
            ),
        ]
    rows = [
        (
            design,
            f"{d.load_sensing.input_energy_J / 1e3:.1f} kJ ({100 * d.load_sensing.system_efficiency:.1f} %)",
            f"{d.constant_pressure.input_energy_J / 1e3:.1f} kJ ({100 * d.constant_pressure.system_efficiency:.1f} %)",
        )
        for design, d in (("initial", h.initial), ("optimal", h.optimal))
    ]
    parts += [
        paragraph(
            "Valve-controlled supplies at the pump motor's electric input over the cycle (system efficiency in "
            "brackets: delivered work over that input)."
        ),
        table(("design", "load sensing", "constant pressure"), rows, numeric=(1, 2)),
    ]
    if battery is None:
        parts.append(
            paragraph(
                "EMLA at the battery per "
                + ("cycle" if result.energy is None else result.energy.period)
                + ": "
                + "; ".join(
                    f"{n} {d.emla_battery_energy_J / 1e3:.2f} kJ"
                    for n, d in (("initial", h.initial), ("optimal", h.optimal))
                )
                + " (not the pump motors' boundary).",
                "note",
            )
        )
    return section(
        "Hydraulic comparison",
        *parts,
        figure(
            folder / "energy_emla_vs_hydraulic.png",
            "EMLA against hydraulic energy over the cycle: the EMLAs at the battery, the cylinders at the pump "
            "motor's electric input (left); each actuator at its own supply (right)",
        ),
    )


def closed_loop(folder: Path) -> str:
    """The closed-loop validation of ``hiab-sim simulate`` when ``simulation.json`` exists.

    The table is the one ``hiab-sim simulate`` prints (:mod:`hiab_sim.design_report.simulation_table`):
    a duty mix's a row per task and design, each against its task's own plan, and a figure per task.
    """
    path = folder / "simulation.json"
    if not path.is_file():
        return ""
    report: dict[str, Any] = json.loads(path.read_text())
    header = table_header(report)
    shift = len(header) - len(COLUMNS)
    return section(
        "Closed-loop validation",
        paragraph(
            "Each design driven by simulated EMLA drives (dq current dynamics, voltage and current limits) under "
            "a tracking controller through the study's cycle; energy integrated at the motor terminals."
        ),
        table(header, table_rows(report), numeric=tuple(i + shift for i in NUMERIC)),
        *(
            figure(
                folder / f"closed_loop_energy{group.suffix}.png",
                f"Cumulative energy{'' if group.task is None else f' of task {group.task}'}, "
                "closed loop against prediction",
            )
            for group in run_groups(report)
        ),
    )


def duty_mix(result: Result, folder: Path) -> str:
    """Per-task energies and the cross-evaluation (the price of robustness) of a duty mix."""
    if not result.tasks:
        return ""
    rows = [
        (
            t.name,
            f"{t.weight:g}",
            f"{t.payload_kg:g} kg",
            f"{t.initial.net_electrical_energy_J:.1f} → {t.optimal.net_electrical_energy_J:.1f} J",
            "–"
            if t.energy is None
            else f"{t.energy.initial.battery_energy_J:.1f} → {t.energy.optimal.battery_energy_J:.1f} J "
            f"(per {t.energy.period})",
        )
        for t in result.tasks
    ]
    parts = [
        table(
            ("task", "weight", "payload", "net energy initial → optimal", "battery energy initial → optimal"),
            rows,
            numeric=(1, 2, 3, 4),
        )
    ]
    c = result.cross_evaluation
    if c is not None:
        cross = [
            (
                design,
                *[num(v, ".1f") for v in c.net_energy_J[i]],
                num(c.mix_net_energy_J[i], ".1f"),
                num(c.mix_energy_lost_percent[i], "+.3f", "%"),
            )
            for i, design in enumerate(c.designs)
        ]
        parts += [
            paragraph(
                "Cross-evaluation: each design on every task, trajectories re-optimised at fixed lengths "
                "(net energy [J])."
            ),
            table(
                ("design", *c.tasks, "mix (weighted)", "mix energy lost"),
                cross,
                numeric=tuple(range(1, len(c.tasks) + 3)),
            ),
            figure(folder / "cross_evaluation.png", "Cross-evaluation"),
        ]
    return section("Duty mix", *parts)


def _initial_optimal(
    initial: Mapping[str, T],
    optimal: Mapping[str, T],
    value: Callable[[T], str],
    detail: Callable[[T], str],
    set_by: Callable[[str], tuple[str, ...]],
) -> list[tuple[str, ...]]:
    """Per name of ``optimal``: the name, both designs' ``value``, the optimal one's ``detail``, ``set_by(name)``."""
    return [(name, value(initial[name]), value(o), detail(o), *set_by(name)) for name, o in optimal.items()]


def _utilisation(b: BucklingSummary) -> str:
    """Largest n f / P_cr [-]; a screw that never pushes (negative: tension throughout) says so."""
    return f"{b.max_utilisation:.3f}" + (" (tension only, never pushed)" if b.peak_push_N <= 0.0 else "")


def structure(result: Result, folder: Path) -> str:
    """Pin loads, screw buckling and natural frequencies of both designs (the result's ``structure`` section).

    A duty mix's section is the envelope over its tasks: every table names the task that sets the
    optimal design's value, and a last table lists each task's own worst values.
    """
    s = result.structure
    if s is None:
        return ""
    e = s.optimal.envelope

    def task(kind: dict[str, str] | str | None, key: str = "") -> tuple[str, ...]:
        if e is None:
            return ()
        name = kind.get(key) if isinstance(kind, dict) else kind
        return (name or "–",)

    mix = () if e is None else ("set by task, optimal",)
    pins = _initial_optimal(
        s.initial.pins,
        s.optimal.pins,
        lambda pin: f"{pin.peak_N / 1e3:.1f} kN",
        lambda pin: f"{pin.magnitude_range_N / 1e3:.1f} kN",
        lambda name: task(None if e is None else e.pin_peak_task, name),
    )
    screws = _initial_optimal(
        s.initial.buckling,
        s.optimal.buckling,
        _utilisation,
        lambda b: f"{b.min_critical_load_N / 1e3:.0f} kN at {b.max_column_length_m:.2f} m",
        lambda name: task(None if e is None else e.buckling_task, name),
    )
    path_task = None if e is None else e.lowest_frequency_trajectory_task
    grid_task = None if e is None else e.lowest_frequency_working_range_task
    freq = [
        (where, num(getattr(s.initial, key), ".2f", "Hz"), num(getattr(s.optimal, key), ".2f", "Hz"), *task(t))
        for where, key, t in (
            ("along the motion", "lowest_frequency_trajectory_Hz", path_task),
            ("over the working range", "lowest_frequency_working_range_Hz", grid_task),
        )
    ]
    most = s.optimal.most_loaded_pin
    where = "" if e is None else f" (task {e.pin_peak_task[most]}, the envelope over the duty mix's tasks)"
    margin = ""
    if e is not None and e.smallest_buckling_margin is not None:
        margin = (
            f" Smallest buckling margin 1 - n f / P_cr over the tasks: {e.smallest_buckling_margin:.3f} "
            f"({e.smallest_buckling_margin_screw} screw, task {e.smallest_buckling_margin_task})."
        )
    parts = [
        paragraph(
            f"Most loaded pin of the optimal design: {most}, {s.optimal.pins[most].peak_N / 1e3:.1f} kN peak{where}. "
            f"Safety factor of the buckling utilisation n = {s.optimal.buckling_safety_factor:g}.{margin} Boundaries: "
            + s.note
            + "."
        ),
        table(("pin", "peak, initial", "peak, optimal", "magnitude range, optimal", *mix), pins, numeric=(1, 2, 3)),
        table(
            ("screw", "utilisation, initial", "utilisation, optimal", "smallest P_cr, optimal", *mix),
            screws,
            numeric=(1, 2),
        ),
        table(("lowest natural frequency", "initial", "optimal", *mix), freq, numeric=(1, 2)),
    ]
    if result.tasks is not None:
        rows = []
        for t in result.tasks:
            if t.structure is None:
                continue
            d = t.structure.optimal
            worst = max(d.buckling.values(), key=lambda b: b.max_utilisation, default=None)
            rows.append(
                (
                    t.name,
                    f"{d.most_loaded_pin}, {d.pins[d.most_loaded_pin].peak_N / 1e3:.1f} kN",
                    num(None if worst is None else worst.max_utilisation, ".3f"),
                    num(d.lowest_frequency_trajectory_Hz, ".2f", "Hz"),
                )
            )
        parts.append(
            table(
                ("task (optimal design)", "most loaded pin", "largest n f / P_cr", "lowest frequency on its motion"),
                rows,
                numeric=(2, 3),
            )
        )
    parts.append(figure(folder / "structure_natural_frequency.png", "Lowest natural frequency over the working range"))
    return section("Structure: pins, screws, natural frequency", *parts)

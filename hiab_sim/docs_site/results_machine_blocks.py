"""Generated blocks of the duty-mix, closed-loop and excavator pages, from those runs' committed data.

Each block is a function of :class:`~hiab_sim.docs_site.results_data.RunData` returning Markdown: the
duty mix's ``tasks`` and ``cross_evaluation``, the default run's ``simulation.json`` (``hiab-sim
simulate --payload-error 0.2``), the eXact excavator's two studies on its machine file and their mix.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from hiab_sim.docs_site.markdown import table
from hiab_sim.docs_site.results_data import RunData
from hiab_sim.docs_site.results_format import CHAINS, LIFT, before_after, kilo, length_headers, lengths, percent_change
from hiab_sim.results.energy_sections import battery_period

MIX, DEFAULT = "xs031_duty_mix", "xs031_spiral"
EXCAVATOR = ("exact_digging", "exact_grading")
#: The excavator's mix of its two tasks (optimize/exact_duty_mix.yaml).
EXCAVATOR_MIX = "exact_duty_mix"


def mix_run(runs: RunData) -> str:
    """How the duty mix's optimum was reached and re-checked."""
    return _run_line(runs, MIX)


def _run_line(runs: RunData, study: str, wall_time: bool = True) -> str:
    """How a mix study's optimum was reached and re-checked (without the wall time where a resumed run's is not one)."""
    r = runs.result(study)
    tasks = r("tasks")
    worst = max(t["recheck"]["max_violation_scaled"] for t in tasks)
    tcp = max(t["recheck"]["tracking_error"]["position_m"] for t in tasks)
    wall = (
        f", {r('solver.total_wall_time_s'):.0f} s for the whole optimisation on the recording machine (shared)"
        if wall_time
        else ""
    )
    return (
        f"Recorded run: {r('solver.iterations')} iterations{wall}, max violation "
        f"{r('solver.max_violation_scaled'):.1e}; each task re-checked on its fine grid with the other ID path: "
        f"max violation ≤ {worst:.1e}, TCP error ≤ {1e3 * tcp:.2f} mm."
    )


def mix_tasks(runs: RunData) -> str:
    """Per task and for the weighted mix: net energy, energy drawn, the lift's peak force at the optimum."""
    r = runs.result(MIX)
    rows: list[tuple[object, ...]] = []
    for t in r("tasks"):
        i, o = t["initial"], t["optimal"]
        load = f", {t['payload_kg']:.0f} kg" if t["payload_kg"] else ""
        rows.append(
            (
                f"{t['name']}{load} ({t['weight']:g})",
                before_after(i["net_electrical_energy_J"], o["net_electrical_energy_J"], digits=0),
                f"{i['drawn_energy_summed_drives_J']:.0f} → {o['drawn_energy_summed_drives_J']:.0f} J",
                f"{kilo(o['actuators'][LIFT]['peak_force_N'], 1)} kN",
            )
        )
    rows.append(
        (
            "mix (weighted)",
            before_after(r("initial.net_electrical_energy_J") / 1e3, r("optimal.net_electrical_energy_J") / 1e3, "kJ"),
            f"{kilo(r('initial.drawn_energy_summed_drives_J'), 1)} → "
            f"{kilo(r('optimal.drawn_energy_summed_drives_J'), 1)} kJ",
            "",
        )
    )
    header = ("task (weight)", "net energy initial → optimal", "drawn, summed drives", f"{LIFT} peak force, optimum")
    return table(header, rows)


def mix_hour(runs: RunData) -> str:
    """The battery's energy over the weighted hour and the motors' hourly RMS torques at the optimum."""
    r = runs.result(MIX)
    rms = r("energy.hourly_rms_torque_Nm")
    torques = ", ".join(f"{v:.2f} N m ({k})" for k, v in rms.items())
    return (
        f"The battery's energy over the weighted hour goes from {kilo(r('energy.initial.battery_energy_J'), 1)} to "
        f"{kilo(r('energy.optimal.battery_energy_J'), 1)} kJ "
        f"({percent_change(r('energy.initial.battery_energy_J'), r('energy.optimal.battery_energy_J'))}); the "
        f"weights read as cycles per hour fill {r('energy.hourly_work_s'):.0f} s of the hour, over which the "
        f"optimum's motors run at RMS torques of {torques}."
    )


def mix_designs(runs: RunData) -> str:
    """The spiral's optimum beside the duty mix's."""
    rows = [
        (label, *(lengths(runs.result(study)("optimal.lengths"), c, 4) for c in CHAINS))
        for label, study in (("spiral alone (the default study)", DEFAULT), ("duty mix", MIX))
    ]
    return table(("design", *length_headers()), rows)


def mix_starts(runs: RunData) -> str:
    """What the duty mix's starts reached (the built crane first, then random feasible ones)."""
    r = runs.result(MIX)
    starts = r("multistart.starts")
    iterations = ", ".join(str(s["iterations"]) for s in starts)
    others = len(starts) - 1
    which = "the built crane" + (f" and {others} random feasible one{'s' * (others > 1)}" if others else "")
    same = "reach one optimum (Xi within 1e-4 m)" if r("multistart.same_optimum") else "reach different optima"
    converged = r("multistart.converged_starts")
    return (
        f"{len(starts)} start{'s' * (len(starts) > 1)} ({which}; {iterations} iterations, {converged} converged) "
        f"{same}."
    )


def _cell(value: float | None, digits: int = 1) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def mix_cross(runs: RunData) -> str:
    """Each task's optimum and the mix's, evaluated on every task and on the mix: net energy [J]."""
    return _cross_table(runs, MIX)


def _cross_table(runs: RunData, study: str) -> str:
    """A mix study's cross-evaluation: each design (rows) on each task and on the mix, net energy [J]."""
    c = runs.result(study)("cross_evaluation")
    rows = []
    for d, design in enumerate(c["designs"]):
        lost, lost_pct = c["mix_energy_lost_J"][d], c["mix_energy_lost_percent"][d]
        rows.append(
            (
                design,
                *(_cell(v) for v in c["net_energy_J"][d]),
                _cell(c["mix_net_energy_J"][d], 0),
                "–" if lost is None else f"{lost:+.0f} J ({lost_pct:+.3f} %)",
            )
        )
    return table(("design", *c["tasks"], "mix (weighted)", "mix energy lost"), rows)


def _closed_loop_row(design: str, run: dict[str, Any], nominal: bool) -> tuple[object, ...]:
    error = run["payload_error"]
    return (
        design,
        "planned" if error == 0 else f"{100 * error:+.0f} %",
        f"{run['predicted_net_electrical_energy_J']:.1f}",
        f"{run['net_electrical_energy_J']:.1f}",
        f"{run['energy_difference_percent']:+.2f} %",
        f"{run['tcp_error_mm']['rms']:.2f} / {run['tcp_error_mm']['max']:.2f}",
        f"{100 * run['current_limit_fraction']:.1f} %",
        f"{100 * run['voltage_limit_fraction']:.1f} %",
        "" if nominal else f"{run['extra_energy_J']:+.1f}",
    )


def closed_loop(runs: RunData) -> str:
    """The table ``hiab-sim simulate --payload-error 0.2`` prints for the default run."""
    rows = []
    for design, run in runs.simulation(DEFAULT)("designs").items():
        if "nominal" in run:
            rows.append(_closed_loop_row(design, run["nominal"], nominal=True))
        rows.append(_closed_loop_row(design, run, nominal="nominal" not in run))
    header = (
        "design",
        "end mass",
        "predicted energy [J]",
        "closed-loop energy [J]",
        "difference",
        "TCP error rms / max [mm]",
        "at current limit",
        "at voltage limit",
        "extra energy [J]",
    )
    return table(header, rows)


def closed_loop_bandwidth(runs: RunData) -> str:
    """The velocity loop's bandwidth against the structure's first natural frequency, per design."""
    designs = runs.simulation(DEFAULT)("designs")
    parts = []
    for design, run in designs.items():
        b = run["bandwidth_check"]
        parts.append(
            f"{design}: f_v = {b['velocity_loop_bandwidth_Hz']:.2f} Hz against f_1 = "
            f"{b['first_natural_frequency_Hz']:.2f} Hz, `bandwidth_margin` = {b['bandwidth_margin']:+.2f}"
        )
    plan = runs.result(DEFAULT)("optimal.tracking_error.position_m")
    return "; ".join(parts) + f". The optimal design's plan itself lies {1e3 * plan:.2f} mm from the TCP reference."


def _recorded(runs: RunData) -> list[str]:
    """The excavator studies with data; NotRecordedError naming the first when neither has any."""
    recorded = [s for s in EXCAVATOR if runs.has(s, "result")]
    if not recorded:
        runs(EXCAVATOR[0], "result")  # raises NotRecordedError naming the study
    return recorded


def excavator_studies(runs: RunData) -> str:
    """Both excavator studies: battery energy built → optimal, iterations, the MuJoCo re-check."""
    recorded = _recorded(runs)
    rows: list[tuple[object, ...]] = []
    for study in EXCAVATOR:
        if study not in recorded:
            rows.append((f"`optimize/{study}.yaml`", "*not recorded yet*", "", "", ""))
            continue
        r = runs.result(study)
        rows.append(
            (
                f"`optimize/{study}.yaml`",
                before_after(
                    r("energy.initial.battery_energy_J") / 1e3, r("energy.optimal.battery_energy_J") / 1e3, "kJ", 3
                )
                + f" per {battery_period(r('energy.duty'))}",
                r("solver.iterations"),
                f"{r('solver.total_wall_time_s'):.0f} s",
                f"max violation {r('recheck.max_violation_scaled'):.1e}, paths differ by "
                f"{r('recheck.force_difference_between_paths_N'):.1e} N",
            )
        )
    header = ("study", "battery energy, built → optimal", "iterations", "wall time (recorded)", "re-check")
    return table(header, rows)


def excavator_designs(runs: RunData) -> str:
    """Every decision variable of the machine file: the file's value and each recorded study's optimum [m]."""
    recorded = _recorded(runs)
    columns = [(f"`{s}` optimum", runs.result(s)("optimal.lengths")["values"]) for s in recorded]
    return _variables_table(runs.result(recorded[0])("initial.lengths"), columns)


def _variables_table(first: dict[str, Any], columns: list[tuple[str, list[float]]]) -> str:
    """Every decision variable [m]: ``first``'s value (the machine file's) and each column's optimum, by label."""
    rows = [
        (f"`{name}`", f"{first['values'][i]:.3f}", *(f"{values[i]:.3f}" for _, values in columns))
        for i, name in enumerate(first["names"])
    ]
    return table(("variable [m]", "machine file", *(label for label, _ in columns)), rows)


def excavator_energy(runs: RunData) -> str:
    """Each recorded cycle at the battery against the machine file's cylinders, and the motors' RMS torques."""
    lines = []
    for study in _recorded(runs):
        r = runs.result(study)
        at = r("hydraulic_baseline.optimal.at_battery")
        torques = ", ".join(
            f"{m} {t['rms_torque_Nm']:.2f} of {t['continuous_torque_Nm']:.1f} N m "
            f"({t['peak_winding_temperature_C']:.1f} °C)"
            for m, t in r("energy.optimal.thermal").items()
        )
        lines.append(
            f"- `{study}`, one cycle at the battery at the optimum: the comparison cylinders would take "
            f"{kilo(at['load_sensing']['cycle_battery_energy_J'], 1)} kJ with load sensing, "
            f"{kilo(at['constant_pressure']['cycle_battery_energy_J'], 1)} kJ at constant pressure and "
            f"{kilo(at['pump_controlled']['cycle_battery_energy_J'], 1)} kJ pump-controlled (one EHA each), against "
            f"{kilo(r('hydraulic_baseline.optimal.emla_cycle_battery_energy_J'), 1)} kJ for the EMLAs; RMS torques "
            f"({r('energy.duty')}): {torques}."
        )
    return "\n".join(lines)


def excavator_mix_run(runs: RunData) -> str:
    """How the excavator mix's optimum was reached and re-checked (its wall time is the page's text: see there)."""
    return _run_line(runs, EXCAVATOR_MIX, wall_time=False)


def excavator_mix_tasks(runs: RunData) -> str:
    """Per task: battery energy per duty period built → optimal; the mix's over the weighted hour."""
    r = runs.result(EXCAVATOR_MIX)
    rows: list[tuple[object, ...]] = []
    for t in r("tasks"):
        i, o = t["energy"]["initial"], t["energy"]["optimal"]
        load = f", {t['payload_kg']:.0f} kg" if t["payload_kg"] else ""
        rows.append(
            (
                f"{t['name']}{load} ({t['weight']:g} per hour, {t['duration_s']:g} s)",
                before_after(i["battery_energy_J"] / 1e3, o["battery_energy_J"] / 1e3, "kJ", 3),
                before_after(
                    t["initial"]["net_electrical_energy_J"] / 1e3,
                    t["optimal"]["net_electrical_energy_J"] / 1e3,
                    "kJ",
                    3,
                ),
            )
        )
    rows.append(
        (
            "mix, the weighted hour",
            before_after(
                r("energy.initial.battery_energy_J") / 1e6, r("energy.optimal.battery_energy_J") / 1e6, "MJ", 3
            ),
            before_after(
                r("initial.net_electrical_energy_J") / 1e6, r("optimal.net_electrical_energy_J") / 1e6, "MJ", 3
            ),
        )
    )
    header = (
        "task (weight, cycle)",
        "battery energy per duty period, built → optimal",
        "net electrical at the drives (hot windings), cycle only",
    )
    rms = ", ".join(f"{m} {v:.2f} N m" for m, v in r("energy.hourly_rms_torque_Nm").items())
    return (
        table(header, rows)
        + f"\n\nThe weights fill {r('energy.hourly_work_s'):.0f} s of the hour with work; the optimum's motors run at "
        f"hourly RMS torques of {rms}."
    )


def excavator_mix_designs(runs: RunData) -> str:
    """Every decision variable [m]: the machine file, each task's study optimum (when recorded) and the mix's."""
    r = runs.result(EXCAVATOR_MIX)
    first = r("initial.lengths")
    columns = [
        (f"`{s}` optimum", runs.result(s)("optimal.lengths")["values"]) for s in EXCAVATOR if runs.has(s, "result")
    ]
    columns.append((f"`{EXCAVATOR_MIX}` optimum", r("optimal.lengths")["values"]))
    return _variables_table(first, columns)


def excavator_mix_cross(runs: RunData) -> str:
    """The excavator mix's cross-evaluation (each task's optimum alone and the mix's on every task)."""
    return _cross_table(runs, EXCAVATOR_MIX)


BLOCKS: dict[str, Callable[[RunData], str]] = {
    "duty-mix-run": mix_run,
    "duty-mix-tasks": mix_tasks,
    "duty-mix-hour": mix_hour,
    "duty-mix-designs": mix_designs,
    "duty-mix-starts": mix_starts,
    "duty-mix-cross": mix_cross,
    "closed-loop": closed_loop,
    "closed-loop-bandwidth": closed_loop_bandwidth,
    "excavator-studies": excavator_studies,
    "excavator-designs": excavator_designs,
    "excavator-energy": excavator_energy,
    "excavator-mix-run": excavator_mix_run,
    "excavator-mix-tasks": excavator_mix_tasks,
    "excavator-mix-designs": excavator_mix_designs,
    "excavator-mix-cross": excavator_mix_cross,
}

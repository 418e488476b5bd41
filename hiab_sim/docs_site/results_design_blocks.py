"""Generated blocks of the default-study and buildable-design pages, from the XS 031 studies' committed data.

Each block is a function of :class:`~hiab_sim.docs_site.results_data.RunData` returning Markdown; the
numbers are the run's (``result.json`` at the path named beside each), in SI units with the unit in
the text.
"""

from __future__ import annotations

from collections.abc import Callable

from hiab_sim.crane.description import LinkLengths
from hiab_sim.docs_site.markdown import table
from hiab_sim.docs_site.results_data import RunData
from hiab_sim.docs_site.results_format import (
    CHAINS,
    LIFT,
    before_after,
    chain_lengths,
    kilo,
    length_headers,
    lengths,
    percent_change,
)
from hiab_sim.study.report.buildable_section import mjcf_command

DEFAULT = "xs031_spiral"


def default_summary(runs: RunData) -> str:
    """The answer in one table: design to build, energies at their boundaries, thermal state, hydraulics."""
    r = runs.result(DEFAULT)
    build = r("buildable.lengths")
    rows = [
        (f"{c} L / Lc0 / Lc, built → to build", f"{lengths(r('initial.lengths'), c)} m → {lengths(build, c)} m")
        for c in CHAINS
    ]
    rows.append(
        (
            "net electrical energy (drive inputs, DC side with the inverter loss)",
            before_after(r("initial.net_electrical_energy_J"), r("optimal.net_electrical_energy_J")),
        )
    )
    rows.append(
        (
            "battery energy per duty period, cycle and rest (at the battery)",
            before_after(r("energy.initial.battery_energy_J"), r("energy.optimal.battery_energy_J")),
        )
    )
    for motor, t in r("energy.optimal.thermal").items():
        rows.append(
            (
                f"{motor} motor at the optimum, {r('energy.duty')}",
                f"RMS torque {t['rms_torque_Nm']:.2f} of {t['continuous_torque_Nm']:.1f} N m, winding "
                f"{t['peak_winding_temperature_C']:.1f} of {t['max_winding_temperature_C']:.0f} °C",
            )
        )
    h = r("hydraulic_baseline.optimal")
    rows.append(
        (
            "hydraulic cylinders, same motion, at the pump motor input (load sensing / constant pressure)",
            f"{kilo(h['load_sensing']['input_energy_J'])} / {kilo(h['constant_pressure']['input_energy_J'])} kJ",
        )
    )
    rows.append(("saving from the lengths alone", f"{r('improvement.decomposition.from_lengths_J'):.1f} J"))
    rows.append(
        (
            f"re-check ({r('recheck.id_path')}, {r('recheck.grid_points')} points): TCP error",
            f"{1e3 * r('recheck.tracking_error.position_m'):.2f} mm",
        )
    )
    return table(("quantity", "value"), rows)


def default_answer(runs: RunData) -> str:
    """The answer in sentences: the design to build and what it saves, with the other studies' headlines."""
    r, energy = runs.result(DEFAULT), runs.result("xs031_spiral_energy")
    code = runs.result("xs031_codesign")
    i, o, b = r("initial.lengths"), r("optimal.lengths"), r("buildable.lengths")
    x0 = {c: (i[c]["Lc0"] + i[c]["Lc"], o[c]["Lc0"] + o[c]["Lc"]) for c in CHAINS}
    lift = r("energy.optimal.thermal")[LIFT]
    battery0 = r("energy.initial.battery_energy_J")
    return (
        "**The answer for the XS 031** (default study): "
        + ", ".join(f"{c} L {i[c]['L']:.3f} → {o[c]['L']:.3f} m" for c in CHAINS)
        + ", retracted actuators x0 = Lc0 + Lc "
        + ", ".join(f"{x0[c][0]:.2f} → {x0[c][1]:.2f} m ({c})" for c in CHAINS)
        + f". Rounded to the {1e3 * r('buildable.tolerance_m'):.0f} mm manufacturing tolerance, the design to build "
        f"is {chain_lengths(b, legend=True)}. Net electrical energy on the "
        f"spiral: {kilo(r('initial.net_electrical_energy_J'))} → {kilo(r('optimal.net_electrical_energy_J'))} kJ "
        f"({percent_change(r('initial.net_electrical_energy_J'), r('optimal.net_electrical_energy_J'), 1)}), "
        f"{r('improvement.decomposition.from_lengths_J'):.0f} J of the saving from the lengths alone. "
        f"The battery's energy per duty period ({r('energy.duty')}) falls "
        f"from {kilo(battery0)} to {kilo(r('energy.optimal.battery_energy_J'))} kJ "
        f"({percent_change(battery0, r('energy.optimal.battery_energy_J'), 1)}; "
        f"{percent_change(battery0, energy('energy.optimal.battery_energy_J'), 1)} to "
        f"{kilo(energy('energy.optimal.battery_energy_J'))} kJ when the battery energy itself is the objective); "
        f"the {LIFT} motor runs at {lift['rms_torque_Nm']:.1f} of {lift['continuous_torque_Nm']:.0f} N m RMS, winding "
        f"{lift['peak_winding_temperature_C']:.0f} of {lift['max_winding_temperature_C']:.0f} °C. Choosing the gear "
        f"ratios with the mounting (`xs031_codesign`) saves {code('codesign.codesign_saving_percent'):.1f} % of the "
        f"battery energy against {code('codesign.mounting_only_saving_percent'):.1f} % for the mounting alone."
    )


def default_answer_mix(runs: RunData) -> str:
    """The duty mix's headline beside the default study's answer."""
    mix, spiral = runs.result("xs031_duty_mix"), runs.result(DEFAULT)("optimal.lengths")
    o = mix("optimal.lengths")
    return (
        f"Designed for the duty mix (`xs031_duty_mix`), the optimum is {chain_lengths(o)} "
        f"(the spiral's: {chain_lengths(spiral)}), "
        f"{percent_change(mix('initial.net_electrical_energy_J'), mix('optimal.net_electrical_energy_J'))} net "
        "energy on the mix."
    )


def default_designs(runs: RunData) -> str:
    """Initial, optimal and rounded design: lengths, net and drawn energy, copper loss (fine grid)."""
    r = runs.result(DEFAULT)
    net0 = r("initial.net_electrical_energy_J")
    rows = []
    for label, design in (("initial (built XS 031)", "initial"), ("optimal", "optimal")):
        net = r(f"{design}.net_electrical_energy_J")
        rows.append(
            (
                label,
                *(lengths(r(f"{design}.lengths"), c, 4) for c in CHAINS),
                f"{net:.1f} J" + ("" if design == "initial" else f" ({percent_change(net0, net)})"),
                f"{r(f'{design}.drawn_energy_summed_drives_J'):.1f} J",
                f"{r(f'{design}.energy_breakdown_J.copper'):.1f} J",
            )
        )
    rows.append(
        (
            f"rounded to {1e3 * r('buildable.tolerance_m'):.0f} mm (buildable)",
            *(lengths(r("buildable.lengths"), c) for c in CHAINS),
            f"{r('buildable.net_electrical_energy_J'):.1f} J",
            "",
            "",
        )
    )
    header = (
        "design",
        *length_headers(),
        "net energy",
        "drawn, summed drives",
        "copper",
    )
    return table(header, rows)


def default_run(runs: RunData) -> str:
    """How the default optimum was reached and checked, and where its saving comes from."""
    r = runs.result(DEFAULT)
    saved = r("improvement.net_energy_saved_J")
    return (
        f"Recorded run: {r('solver.iterations')} SQP iterations in {r('solver.total_wall_time_s'):.1f} s "
        f"(the recording machine, shared), max violation {r('solver.max_violation_scaled'):.1e}; re-check on "
        f"{r('recheck.grid_points')} points with the {r('recheck.id_path')} path: max violation "
        f"{r('recheck.max_violation_scaled'):.1e}, TCP error {1e3 * r('recheck.tracking_error.position_m'):.2f} mm, "
        f"the two ID paths' forces differ by {r('recheck.force_difference_between_paths_N'):.1e} N. Of the "
        f"{saved:.1f} J saved, {r('improvement.decomposition.from_lengths_J'):.1f} J come from the lengths alone "
        f"(optimal Xi on the initial trajectory) and {r('improvement.decomposition.from_trajectory_J'):.1f} J "
        "from re-shaping the trajectory inside the tracking bands (`improvement.decomposition`; the two "
        "overlap by their interaction)."
    )


def other_studies(runs: RunData) -> str:
    """The payload study and the seed-scale study beside the default one."""
    rows = []
    for study, label in (
        (DEFAULT, "`xs031_spiral` (default)"),
        ("xs031_spiral_payload", "`xs031_spiral_payload` (150 kg at the TCP)"),
        ("seed_scale_spiral", "`seed_scale_spiral` (the seed's Xi, crane scaled)"),
    ):
        r = runs.result(study)
        rows.append(
            (
                label,
                r("solver.iterations"),
                before_after(
                    r("initial.net_electrical_energy_J") / 1e3, r("optimal.net_electrical_energy_J") / 1e3, "kJ", 2
                ),
                f"{r('improvement.decomposition.from_lengths_J'):.1f} J",
                *(lengths(r("optimal.lengths"), c, 4) for c in CHAINS),
            )
        )
    header = ("study", "iterations", "net energy", "from the lengths alone", *length_headers(legend_once=True))
    return table(header, rows)


def buildable_designs(runs: RunData) -> str:
    """Per study: the rounded design, its ±tolerance worst margin, the fine-grid re-check, its net energy."""
    rows = []
    for study in (DEFAULT, "xs031_spiral_payload", "seed_scale_spiral"):
        r = runs.result(study)
        b = r("buildable.lengths")
        rows.append(
            (
                f"`{study}`",
                ", ".join(lengths(b, c) for c in CHAINS),
                f"{1e6 * r('buildable.tolerance_check.margin'):+.1f} µm",
                f"{r('buildable.recheck.margin'):.1e}",
                f"{r('buildable.net_electrical_energy_J'):.1f} J "
                f"(optimum {r('optimal.net_electrical_energy_J'):.1f} J)",
            )
        )
    header = (
        "study",
        f"rounded design ({', '.join(CHAINS)} L / Lc0 / Lc) [m]",
        "±1 mm worst margin",
        "fine-grid re-check",
        "net energy",
    )
    return table(header, rows)


def buildable_range(runs: RunData) -> str:
    """The default study's export command and the joint range its stroke margin gives up."""
    r = runs.result(DEFAULT)
    given = r("buildable.range_given_up_deg")
    parts = [f"{c} {low:.2f}° at the low end and {up:.2f}° at the up end" for c, (low, up) in given.items()]
    b = r("buildable.lengths")
    rounded = LinkLengths.from_array([b[c][k] for c in CHAINS for k in ("L", "Lc0", "Lc")])
    command = mjcf_command(r("crane"), r("buildable.stroke_margin_m"), rounded)
    return (
        f"`{command}` accepts the default study's rounded design. The "
        f"{1e3 * r('buildable.stroke_margin_m'):.0f} mm stroke margin costs joint range: " + "; ".join(parts) + "."
    )


def sensitivity(runs: RunData) -> str:
    """The default study's active constraints: objective decrease per unit relaxed, in % of the optimum's."""
    r = runs.result(DEFAULT)
    rows = [
        (f"`{m['constraint']}`", f"{m['percent_per_unit']:.4f} %/{m['unit']}") for m in r("sensitivity.multipliers")
    ]
    return table((f"active constraint (objective {r('sensitivity.objective')})", "decrease per unit relaxed"), rows)


def mounting(runs: RunData) -> str:
    """The mounting-space study: its rounded optimum and net energy against its start."""
    r, default = runs.result("xs031_spiral_mounting"), runs.result(DEFAULT)
    b = r("buildable.lengths")
    default_change = percent_change(
        default("initial.net_electrical_energy_J"), default("optimal.net_electrical_energy_J")
    )
    return (
        f"`xs031_spiral_mounting` (recorded): the optimum rounds to {chain_lengths(b)}; net energy "
        f"{before_after(r('initial.net_electrical_energy_J'), r('optimal.net_electrical_energy_J'))}, "
        f"against {default_change} for the default study; duty: {r('energy.duty')}."
    )


BLOCKS: dict[str, Callable[[RunData], str]] = {
    "default-study": default_summary,
    "default-answer": default_answer,
    "default-answer-mix": default_answer_mix,
    "default-designs": default_designs,
    "default-run": default_run,
    "default-other-studies": other_studies,
    "buildable-designs": buildable_designs,
    "buildable-range": buildable_range,
    "buildable-sensitivity": sensitivity,
    "buildable-mounting": mounting,
}

"""What each plant effect costs: the closed loop of both designs on the ideal plant, on each effect alone, and on all.

For a plant (:mod:`hiab_sim.env.plant`) and a result folder, every variant (``ideal``: every effect off;
one per effect the plant enables; ``all``: the plant itself) runs ``cycles`` cycles of each design
under the cascade controller (:func:`hiab_sim.env.rollout.run_closed_loop`). Per variant and design
the report holds the DC-bus energy against the optimiser's prediction, the TCP error (rms, max), the
peak currents and voltages, and whether the optimal design stays cheaper than the initial one; per
effect its share of the all-effects energy difference to the ideal plant, (E_effect - E_ideal) /
(E_all - E_ideal) (the shares need not add to 1: the effects interact).

With a mass mismatch the report also gives the prediction of the same planned motion at the true
masses (MuJoCo inverse dynamics of the true crane, the planner's steady-state EMLA model,
eq. ``costf2``'s P_elec integrated by the trapezoid rule), which splits the mismatch's extra energy
into the cost of the heavier load (true-mass prediction - prediction) and the cost of tracking
without knowing it (closed loop - true-mass prediction). Beside them stands the plan re-optimised
for the true masses (:func:`replanned_prediction`: the study solved again with the true crane), the
energy a planner that knew the load would have predicted for its own optimum.
"""

from __future__ import annotations

import json
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla import electrical_power
from hiab_sim.emla.duty_energy import drive_duty
from hiab_sim.env.plan import DesignPlan, read_plan
from hiab_sim.env.plant.config import Plant
from hiab_sim.env.plant.mismatch import true_crane
from hiab_sim.env.rollout import run_closed_loop
from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.style import COLOURS


def variants(plant: Plant) -> list[Plant]:
    """ideal, each enabled effect alone, and all of them (``all``) when more than one is on."""
    out = [plant.ideal()] + [plant.only(name) for name in plant.enabled]
    if len(plant.enabled) > 1:
        out.append(plant.with_effects(plant.enabled, "all"))
    return out


def true_mass_prediction(plan: DesignPlan, plant: Plant) -> float:
    """Predicted net electrical energy [J] of the planned motion at the mismatch's true masses (module docstring)."""
    crane = true_crane(plan.crane, plant.mismatch)
    joints = JointSamples(plan.position, plan.velocity, plan.acceleration)
    dynamics = MujocoInverseDynamics(crane, plan.lengths)
    tcp_force = None if plan.payload == 0.0 else np.array([0.0, -plan.payload * crane.gravity, 0.0])
    actuators = dynamics(joints, tcp_force)
    samples = [
        (actuators.force[:, i], actuators.velocity[:, i], actuators.acceleration[:, i]) for i in range(len(plan.emlas))
    ]
    if plan.duty is None:  # the paper's per-sample model
        power = sum(electrical_power(params, *x) for params, x in zip(plan.emlas, samples, strict=True))
    else:  # the study's duty model, as the optimiser's energy: hot windings, the brake's coil
        grid = plan.time - plan.time[0]
        power = sum(
            drive_duty(params, grid, *x, plan.duty).power for params, x in zip(plan.emlas, samples, strict=True)
        )
    total = np.asarray(power, dtype=float)
    return float(0.5 * np.sum((total[1:] + total[:-1]) * np.diff(plan.time)))


def replanned_prediction(result_dir: str | Path, plant: Plant) -> dict[str, object]:
    """The result's study optimised again with the mismatch's true crane: its optimum's predicted energy [J].

    Returns a mapping with ``predicted_J`` and ``lengths`` of the re-optimised design, or with
    ``skipped`` saying why (the study file is gone, or the study is a mix of tasks).
    """
    from hiab_sim.results.read import read_result
    from hiab_sim.study.run import run_study
    from hiab_sim.study.spec.study_file import load_study

    study = load_study(read_result(result_dir).study)
    if len(study.tasks) != 1:
        return {"skipped": f"the study has {len(study.tasks)} tasks; re-planning is done for single-task studies"}
    true_study = replace(study, crane_description=true_crane(study.crane, plant.mismatch))
    with tempfile.TemporaryDirectory(prefix="hiab_sim_replan_") as folder:
        out = run_study(true_study, Path(folder) / "replan", progress=None, figures=False, force=True, cross=False)
        result = json.loads((out.folder / "result.json").read_text(encoding="utf-8"))
    optimal = result["optimal"]
    return {"predicted_J": float(optimal["net_electrical_energy_J"]), "lengths": optimal.get("lengths")}


def _entry(summary: dict[str, object]) -> dict[str, object]:
    keys = (
        "dc_bus_energy_J",
        "net_electrical_energy_J",
        "predicted_net_electrical_energy_J",
        "dc_bus_energy_difference_percent",
        "predicted_net_electrical_energy_5ms_grid_J",
        "energy_difference_to_5ms_grid_percent",
        "tcp_error_mm",
        "copper_loss_J",
        "inverter_loss_J",
        "transmission_loss_J",
        "brake_coil_energy_J",
        "motor_terminal_energy_J",
        "drive_train_loss_J",
        "joint_friction_loss_J",
        "winding_temperature_C",
        "current_limit_fraction",
        "voltage_limit_fraction",
        "cycles",
    )
    entry = {key: summary[key] for key in keys}
    actuators = summary["actuators"]
    assert isinstance(actuators, dict)
    entry["peak_current_A"] = {name: a["peak_current_A"] for name, a in actuators.items()}
    entry["peak_voltage_V"] = {name: a["peak_voltage_V"] for name, a in actuators.items()}
    return entry


def effect_study(
    result_dir: str | Path,
    plant: Plant,
    cycles: int = 1,
    designs: tuple[str, ...] = ("initial", "optimal"),
    quiet: bool = False,
) -> dict[str, object]:
    """The ``plant_effects`` section of ``simulation.json`` (module docstring)."""
    plans = {design: read_plan(result_dir, design) for design in designs}
    table: dict[str, dict[str, object]] = {}
    runs = [(variant, design) for variant in variants(plant) for design in designs]
    for variant, design in tqdm(runs, desc="plant effects", disable=quiet, file=sys.stderr, leave=False):
        run, physics = run_closed_loop(plans[design], plant=variant, cycles=cycles)
        physics.free()
        table.setdefault(variant.name, {})[design] = _entry(run.summary())
        table[variant.name]["gains_rad_per_s"] = {
            "position": run.gains.position,
            "velocity": run.gains.velocity,
            "integral": run.gains.integral,
        }
        table[variant.name]["lowest_drive_train_resonance_Hz"] = run.lowest_resonance_hz
    for entry in table.values():
        if all(d in entry for d in ("initial", "optimal")):
            energy = {d: float(entry[d]["dc_bus_energy_J"]) for d in ("initial", "optimal")}  # type: ignore[index]
            entry["optimal_below_initial"] = energy["optimal"] < energy["initial"]
    report: dict[str, object] = {
        "plant": plant.name,
        "cycles": cycles,
        "effects_on": list(plant.enabled),
        "variants": table,
        "energy": "DC-bus energy: the drives' DC inputs (int 3/2 (v_d i_d + v_q i_q) dt with the EMLA file's inverter "
        "loss and holding brake), all drives, last cycle",
        "provenance": dict(plant.provenance),
    }
    top = "all" if "all" in table else (plant.enabled[0] if plant.enabled else None)
    if top is not None:
        shares: dict[str, dict[str, float]] = {}
        for design in designs:
            ideal = float(table["ideal"][design]["dc_bus_energy_J"])  # type: ignore[index]
            whole = float(table[top][design]["dc_bus_energy_J"]) - ideal  # type: ignore[index]
            shares[design] = {
                name: (float(table[name][design]["dc_bus_energy_J"]) - ideal) / whole  # type: ignore[index]
                for name in plant.enabled
                if whole != 0.0
            }
        report["share_of_energy_difference"] = shares
    if plant.mismatch.enabled:
        split: dict[str, dict[str, float]] = {}
        for design, plan in plans.items():
            true = true_mass_prediction(plan, plant)
            closed = float(table["mismatch"][design]["net_electrical_energy_J"])  # type: ignore[index]
            split[design] = {
                "predicted_J": plan.predicted_net_energy,
                "predicted_at_true_masses_J": true,
                "closed_loop_J": closed,
                "cost_of_heavier_load_J": true - plan.predicted_net_energy,
                "cost_of_mismatch_J": closed - true,
            }
        replanned = replanned_prediction(result_dir, plant)
        report["mismatch_replanned"] = replanned
        if "predicted_J" in replanned:
            for row in split.values():
                row["replanned_optimum_predicted_J"] = float(replanned["predicted_J"])  # type: ignore[arg-type]
        report["mismatch_split"] = split
    return report


def effect_table(report: dict[str, object]) -> str:
    """Markdown table of the effect study (docs/plant.md's table)."""
    lines = [
        "| plant | design | DC-bus energy [J] | vs predicted | vs 5 ms grid | TCP error rms / max [mm] "
        "| peak currents [A] | peak voltages [V] | optimal cheaper |",
        "|---|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    table = report["variants"]
    assert isinstance(table, dict)
    for name, entry in table.items():
        for design in ("initial", "optimal"):
            if design not in entry:
                continue
            row = entry[design]
            tcp = row["tcp_error_mm"]
            currents = " / ".join(f"{v:.1f}" for v in row["peak_current_A"].values())
            voltages = " / ".join(f"{v:.0f}" for v in row["peak_voltage_V"].values())
            cheaper = (
                {True: "yes", False: "**no**"}.get(entry.get("optimal_below_initial"), "")
                if design == "optimal"
                else ""
            )
            fine = row.get("energy_difference_to_5ms_grid_percent")
            lines.append(
                f"| {name} | {design} | {row['dc_bus_energy_J']:.1f} "
                f"| {row['dc_bus_energy_difference_percent']:+.2f} % "
                f"| {'' if fine is None else format(fine, '+.2f') + ' %'} "
                f"| {tcp['rms']:.2f} / {tcp['max']:.2f} | {currents} | {voltages} | {cheaper} |"
            )
    return "\n".join(lines)


def effect_figure(path: Path, report: dict[str, object]) -> Path:
    """Bar chart: DC-bus energy difference to the prediction per variant and design [%]."""
    table = report["variants"]
    assert isinstance(table, dict)
    names = list(table)
    fig = new_figure((8.0, 3.6))
    ax = fig.add_subplot()
    x = np.arange(len(names))
    for offset, design in ((-0.2, "initial"), (0.2, "optimal")):
        values = [table[n][design]["dc_bus_energy_difference_percent"] if design in table[n] else np.nan for n in names]
        ax.bar(x + offset, values, width=0.4, color=COLOURS.get(design, COLOURS["reference"]), label=design)
    ax.set_xticks(x, names, rotation=20)
    ax.axhline(0.0, color="k", linewidth=0.8)
    ax.set(
        ylabel="closed loop vs predicted [%]", title=f"Closed-loop DC-bus energy per plant effect ({report['plant']})"
    )
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8)
    return save_png(fig, path, 110)

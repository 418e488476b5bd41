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
for the true masses (:func:`replanned_predictions`: the study solved again with the true crane), the
energy a planner that knew the load would have predicted for its own optimum; a duty mix is solved
again once, and each task's effect study gets that optimum's energy of the task's own cycle.

One code path for a crane file's result and a machine file's (:func:`read_any_plan`,
:func:`run_plan`): on a machine file the true masses are :func:`~hiab_sim.env.plant.mismatch.true_machine`'s
and the true payload the planned one x (1 + e_end) (its weight through the TCP force, at the TCP:
the centre-of-mass offset is simulated, not predicted, as the planner's TCP load is a force at
the TCP), and the re-planned study is the machine study with that machine and payload. Where the
result has a battery (``result.json`` ``energy``), each entry also holds the closed loop's battery
energy against the result's (:mod:`hiab_sim.env.closed_loop_battery`: one cycle, the rest between cycles left out).

The report's tables, ``effects.md`` and figure are :mod:`hiab_sim.env.effect_report`'s.
"""

from __future__ import annotations

import json
import sys
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples
from hiab_sim.emla import electrical_power
from hiab_sim.emla.duty_energy import drive_duty
from hiab_sim.env.closed_loop_battery import BATTERY_NOTE, battery_entry, predicted_cycle_battery_energy
from hiab_sim.env.machine_env import run_machine_closed_loop
from hiab_sim.env.machine_plan import MachinePlan, is_machine_result, read_machine_plan
from hiab_sim.env.physics import CranePhysics
from hiab_sim.env.plan import DesignPlan, read_plan
from hiab_sim.env.plant.config import Plant
from hiab_sim.env.plant.mismatch import payload_factor, true_crane, true_machine
from hiab_sim.env.rollout import ClosedLoopRun, run_closed_loop
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.dynamics.tree import MachineActuatorSamples
from hiab_sim.study.spec.study import Study
from hiab_sim.terminal import progress_wanted


def variants(plant: Plant) -> list[Plant]:
    """ideal, each enabled effect alone, and all of them (``all``) when more than one is on."""
    out = [plant.ideal()] + [plant.only(name) for name in plant.enabled]
    if len(plant.enabled) > 1:
        out.append(plant.with_effects(plant.enabled, "all"))
    return out


def read_any_plan(result_dir: str | Path, design: str, task: int | None = None) -> DesignPlan | MachinePlan:
    """One design's plan of a crane file's result (:func:`read_plan`) or a machine file's (``read_machine_plan``).

    ``task``: the index k of a duty mix's task (its own plan), None for a single-task result.
    """
    if is_machine_result(result_dir):
        return read_machine_plan(result_dir, design, task)
    return read_plan(result_dir, design, task)


def run_plan(plan: DesignPlan | MachinePlan, plant: Plant, cycles: int) -> tuple[ClosedLoopRun, CranePhysics]:
    """``cycles`` closed-loop cycles of a crane's or a machine's plan on ``plant`` (the log and the Physics)."""
    if isinstance(plan, MachinePlan):
        return run_machine_closed_loop(plan, plant=plant, cycles=cycles)
    return run_closed_loop(plan, plant=plant, cycles=cycles)


def _true_actuators(plan: DesignPlan | MachinePlan, plant: Plant) -> ActuatorSamples | MachineActuatorSamples:
    """The planned motion's actuator samples on the plan's grid at the mismatch's true masses (module docstring)."""
    if isinstance(plan, MachinePlan):
        machine = true_machine(plan.machine, plant.mismatch)
        force = plan.tcp_force + (payload_factor(plant.mismatch) - 1.0) * plan.payload_force
        return MujocoMachineDynamics(machine)(plan.position, plan.velocity, plan.acceleration, tcp_force=force[:, :2])
    crane = true_crane(plan.crane, plant.mismatch)
    joints = JointSamples(plan.position, plan.velocity, plan.acceleration)
    dynamics = MujocoInverseDynamics(crane, plan.lengths)
    return dynamics(joints, plan.id_tcp_force())


def true_mass_prediction(plan: DesignPlan | MachinePlan, plant: Plant) -> float:
    """Predicted net electrical energy [J] of the planned motion at the mismatch's true masses (module docstring)."""
    actuators = _true_actuators(plan, plant)
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


def true_study(study: Study, plant: Plant) -> Study:
    """The study with the mismatch's true masses (the true machine and payload, or the true crane).

    A machine file's study gets :func:`~hiab_sim.env.plant.mismatch.true_machine` and every task's
    payload x (1 + e_end), as the closed loop of each task's plan carries it; a crane file's
    :func:`~hiab_sim.env.plant.mismatch.true_crane`.
    """
    if study.machine is not None:
        factor = payload_factor(plant.mismatch)
        tasks = tuple(replace(t, payload=replace(t.payload, mass=t.payload.mass * factor)) for t in study.tasks)
        return replace(study, machine=true_machine(study.machine, plant.mismatch), tasks=tasks)
    return replace(study, crane_description=true_crane(study.crane, plant.mismatch))


def replanned_summary(result_dir: str | Path, task: int | None = None) -> dict[str, object]:
    """``predicted_J``, ``lengths`` (and ``predicted_battery_J`` with a battery) of a re-planned result folder.

    ``predicted_battery_J`` is the re-planned optimum's battery energy of one cycle, the boundary of the
    closed loop's and of the nominal prediction (``predicted_cycle_battery_energy`` of
    :mod:`hiab_sim.env.closed_loop_battery`: with the study's duty model the cycle's share, the rest
    between cycles left out). ``task``: the index k of a duty mix's task, whose own cycle's energies
    (``tasks[k]``) are given, with its name under ``task``; ``lengths`` are the mix's one design.
    """
    result = json.loads((Path(result_dir) / "result.json").read_text(encoding="utf-8"))
    optimal = result["optimal"] if task is None else result["tasks"][task]["optimal"]
    replanned: dict[str, object] = {
        "predicted_J": float(optimal["net_electrical_energy_J"]),
        "lengths": result["optimal"].get("lengths"),
    }
    if task is not None:
        replanned["task"] = result["tasks"][task]["name"]
    battery = predicted_cycle_battery_energy(result_dir, task)
    if "optimal" in battery:
        replanned["predicted_battery_J"] = float(battery["optimal"])
    return replanned


def replanned_predictions(result_dir: str | Path, plant: Plant) -> list[dict[str, object]]:
    """The result's study optimised again with the mismatch's true masses (:func:`true_study`): its optimum's energy.

    Returns :func:`replanned_summary`'s mapping of the re-optimised design, one per task: a single
    task's, or each task's of a duty mix (the mix is solved once, its one design serving every task).

    Raises:
        ConfigError: the study file is gone.

    """
    from hiab_sim.results.read import read_result
    from hiab_sim.study.run import run_study
    from hiab_sim.study.spec.study_file import load_study

    study = load_study(read_result(result_dir).study)
    with tempfile.TemporaryDirectory(prefix="hiab_sim_replan_") as folder:
        out = run_study(
            true_study(study, plant), Path(folder) / "replan", progress=None, figures=False, force=True, cross=False
        )
        if len(study.tasks) == 1 and read_result(out.folder).tasks is None:
            return [replanned_summary(out.folder)]
        return [replanned_summary(out.folder, k) for k in range(len(study.tasks))]


def attach_replanned(report: dict[str, Any], replanned: dict[str, object]) -> None:
    """Put the re-planned prediction into an effect study's report, beside each design's mismatch split."""
    report["mismatch_replanned"] = replanned
    for row in report["mismatch_split"].values():
        if "predicted_J" in replanned:
            row["replanned_optimum_predicted_J"] = float(replanned["predicted_J"])  # type: ignore[arg-type]
        if "closed_loop_battery_J" in row and "predicted_battery_J" in replanned:
            row["replanned_optimum_predicted_battery_J"] = float(replanned["predicted_battery_J"])  # type: ignore[arg-type]


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
    replan: bool = True,
    task: int | None = None,
) -> dict[str, object]:
    """The ``plant_effects`` section of ``simulation.json`` (module docstring).

    ``replan`` False leaves the re-planned prediction out (the study's optimisation again, minutes;
    :func:`attach_replanned` adds one computed elsewhere: a duty mix's caller solves the mix once for
    all its tasks). ``task``: the index k of a duty mix's task, whose own plans run and whose own
    cycle's energies they are compared with (``result.json`` ``tasks[k]``, and the re-planned mix's
    ``tasks[k]``, :func:`replanned_predictions`).
    """
    plans = {design: read_any_plan(result_dir, design, task) for design in designs}
    battery = predicted_cycle_battery_energy(result_dir, task)
    table: dict[str, dict[str, object]] = {}
    runs = [(variant, design) for variant in variants(plant) for design in designs]
    hidden = quiet or not progress_wanted()  # redirected to a file, a bar would dump its updates into the log
    for variant, design in tqdm(runs, desc="plant effects", disable=hidden, file=sys.stderr, leave=False):
        run, physics = run_plan(plans[design], variant, cycles)
        physics.free()
        entry = _entry(run.summary())
        if design in battery:
            entry.update(battery_entry(run, plans[design].emlas.battery, battery[design]))
        table.setdefault(variant.name, {})[design] = entry
        table[variant.name]["gains_rad_per_s"] = {
            "position": run.gains.position,
            "velocity": run.gains.velocity,
            "integral": run.gains.integral,
        }
        table[variant.name]["lowest_drive_train_resonance_Hz"] = run.lowest_resonance_hz
    keys = ["dc_bus_energy_J"]
    if all("battery_energy_J" in entry[d] for entry in table.values() for d in designs):  # type: ignore[operator]
        keys.append("battery_energy_J")
    for entry in table.values():
        if all(d in entry for d in ("initial", "optimal")):
            for key in keys:
                energy = {d: float(entry[d][key]) for d in ("initial", "optimal")}  # type: ignore[index]
                entry[_CHEAPER[key]] = energy["optimal"] < energy["initial"]
    report: dict[str, object] = {
        "plant": plant.name,
        "task": next(iter(plans.values())).task,  # a duty mix's task (its name), None for a single task
        "cycles": cycles,
        "effects_on": list(plant.enabled),
        "variants": table,
        "energy": "DC-bus energy: the drives' DC inputs (int 3/2 (v_d i_d + v_q i_q) dt with the EMLA file's inverter "
        "loss and holding brake), all drives, last cycle",
        "provenance": dict(plant.provenance),
    }
    if "battery_energy_J" in keys:
        report["battery_energy"] = BATTERY_NOTE
    top = "all" if "all" in table else (plant.enabled[0] if plant.enabled else None)
    if top is not None:
        for key in keys:
            report[_SHARE[key]] = _shares(table, designs, plant.enabled, top, key)
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
        for design, row in split.items():
            mismatch = table["mismatch"][design]
            if "battery_energy_J" in mismatch:  # type: ignore[operator]
                row["closed_loop_battery_J"] = float(mismatch["battery_energy_J"])  # type: ignore[index]
                row["predicted_battery_J"] = float(battery[design])
        report["mismatch_split"] = split
        if replan:
            attach_replanned(report, replanned_predictions(result_dir, plant)[0 if task is None else task])
    return report


#: Per energy: the key of "the optimal design draws less than the initial one" and of the effects' shares.
_CHEAPER = {"dc_bus_energy_J": "optimal_below_initial", "battery_energy_J": "optimal_below_initial_battery"}
_SHARE = {"dc_bus_energy_J": "share_of_energy_difference", "battery_energy_J": "share_of_battery_energy_difference"}


def _shares(
    table: dict[str, dict[str, object]], designs: tuple[str, ...], enabled: tuple[str, ...], top: str, key: str
) -> dict[str, dict[str, float]]:
    """Per design and effect (E_effect - E_ideal) / (E_top - E_ideal) of the energy ``key`` (module docstring)."""
    shares: dict[str, dict[str, float]] = {}
    for design in designs:
        ideal = float(table["ideal"][design][key])  # type: ignore[index]
        whole = float(table[top][design][key]) - ideal  # type: ignore[index]
        shares[design] = {
            name: (float(table[name][design][key]) - ideal) / whole  # type: ignore[index]
            for name in enabled
            if whole != 0.0
        }
    return shares

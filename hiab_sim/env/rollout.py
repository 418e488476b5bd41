"""One closed-loop cycle of a design: the cascade controller on the environment, logged and summarised.

Energies come from the drives' exact per-step integrals (:mod:`hiab_sim.emla.drive_sim`) and the EMLA
file's drive losses (:mod:`hiab_sim.env.drive_losses`): the net electrical energy is each drive's DC
input (the motor terminals' int 3/2 (v_d i_d + v_q i_q) dt with the brake's release factor, plus the
inverter's loss and the brake coil's power) over the cycle, summed over the drives (the DC bus credits
regeneration of one drive to the others): the boundary of the optimiser's number for the design
(``result.json``), whose predicted power is the plan's P_elec on its fine grid.

The gains follow the design rules of :mod:`hiab_sim.control.cascade` for the plan's crane and the
plant (:mod:`hiab_sim.env.loop_design`: the structure's lowest natural frequency, a compliant
drive train's lowest resonance), and every run carries the check of its velocity-loop bandwidth
against the structure's lowest natural frequency (``bandwidth_check``). With a plant
(:mod:`hiab_sim.env.plant`) ``cycles`` > 1
runs the cycle repeatedly with the winding temperature carried over (cooling over the plant's rest
between cycles); the log is the last cycle's, the per-cycle energies and temperatures are kept.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Protocol

import dm_env
import numpy as np
from dm_control.rl import control

from hiab_sim.arrays import Array
from hiab_sim.control.cascade import CascadeController, CascadeGains
from hiab_sim.emla.config import ACTUATOR_NAMES
from hiab_sim.emla.drive_sim import DriveArrays
from hiab_sim.env import make_environment
from hiab_sim.env.loop_design import LoopDesign, design_loop
from hiab_sim.env.physics import CranePhysics
from hiab_sim.env.plan import DesignPlan
from hiab_sim.env.planned_energy import resampled_prediction
from hiab_sim.env.plant.config import Plant
from hiab_sim.errors import InvalidInputError
from hiab_sim.percent import change_percent
from hiab_sim.quadrature import trapezoid


class PlanLike(Protocol):
    """What a run's log compares against: the plan's fine grid [s], its P_elec per drive [W], its energy [J]."""

    @property
    def time(self) -> Array: ...  # noqa: D102

    @property
    def predicted_electrical_power(self) -> Array: ...  # noqa: D102

    @property
    def predicted_net_energy(self) -> float: ...  # noqa: D102


@dataclass(frozen=True)
class ClosedLoopRun:
    """The log of one cycle; series are sampled at every control step, (N,) or (N, 3) or (N, 3, 2).

    Attributes:
        design: ``initial`` or ``optimal``.
        payload_error: Relative end-mass error of the simulated crane.
        time: [s].
        tcp_error: |p_tcp - p_ref| [m], to the study's TCP reference.
        plan_error: |p_tcp - p_plan| [m], to the TCP of the planned motion (the controller's own error).
        current_dq, voltage_dq: (d, q) per drive at the end of each step [A, V].
        electrical_power: Mean P_elec per drive over each control step [W].
        cumulative_energy: int P_elec dt per drive up to each time [J], at the drive's DC input.
        plan_time, predicted_power: The plan's fine grid [s] and P_elec per actuator there [W].
        predicted_net_energy: The optimiser's net electrical energy [J].
        current_limit, voltage_limit: I_max [A] and V_max = |v_dq| limit [V] per drive.
        current_limit_fraction, voltage_limit_fraction: Fraction of physics steps at each limit, per drive.
        copper_energy: int 3/2 R_s |i|^2 dt per drive [J].
        qpos: Joint positions at every control step, for rendering (N, nq).
        wall_time: Wall-clock seconds of the simulation loop.
        plant: Name of the plant (``ideal``: the planner's model).
        inverter_energy: The inverters' loss per drive over the cycle [J] (in ``cumulative_energy``).
        terminal_energy: int 3/2 v.i dt per drive at the motor terminals over the cycle [J].
        transmission_loss: The screw and gearbox loss per drive over the cycle [J].
        brake_coil_energy: The released holding brakes' coil energy per drive [J] (in ``cumulative_energy``).
        brake_carried: Motor-terminal energy the engaged brake saves per drive, (1 - s) E_m [J].
        drive_train_loss: Screw friction and spring damping of the two-mass drive train per drive [J].
        friction_loss: Dissipated in the hinges and pins over the cycle [J].
        winding_temperature: Winding temperature per drive at the end of the cycle [deg C], or None.
        cycles: Per cycle: DC-bus energy [J] and end winding temperatures [deg C].
        gains: The controller's loop bandwidths.
        lowest_resonance_hz: The lowest drive-train resonance the gains were designed against [Hz], or None.
        bandwidth_check: The velocity-loop bandwidth against the structure's lowest natural frequency
            (:meth:`hiab_sim.env.loop_design.LoopDesign.check`).
        settle_time_s: Simulated hold before each cycle (:func:`settled_start`) [s], not in ``time``.
        resampled_prediction: The planner's energy of the plan on a 5 ms grid [J] (:func:`resampled_prediction`),
            or None.
        task: The name of the duty mix's task whose plan ran (:attr:`hiab_sim.env.plan.PlannedDesign.task`),
            None for a single-task result.

    """

    design: str
    payload_error: float
    time: Array
    tcp_error: Array
    plan_error: Array
    current_dq: Array
    voltage_dq: Array
    electrical_power: Array
    cumulative_energy: Array
    plan_time: Array
    predicted_power: Array
    predicted_net_energy: float
    current_limit: Array
    voltage_limit: Array
    current_limit_fraction: Array
    voltage_limit_fraction: Array
    copper_energy: Array
    qpos: Array
    wall_time: float
    plant: str = "ideal"
    inverter_energy: Array | None = None
    terminal_energy: Array | None = None
    transmission_loss: Array | None = None
    brake_coil_energy: Array | None = None
    brake_carried: Array | None = None
    drive_train_loss: Array | None = None
    friction_loss: float = 0.0
    winding_temperature: Array | None = None
    cycles: tuple[dict[str, object], ...] = ()
    gains: CascadeGains = field(default_factory=CascadeGains)
    lowest_resonance_hz: float | None = None
    bandwidth_check: dict[str, object] = field(default_factory=dict)
    settle_time_s: float = 0.0
    actuator_names: tuple[str, ...] = ACTUATOR_NAMES
    resampled_prediction: float | None = None
    task: str | None = None

    @property
    def net_energy(self) -> float:
        """Closed-loop net electrical energy of all drives at their DC inputs (the prediction's boundary) [J]."""
        return float(self.cumulative_energy[-1].sum())

    @property
    def bus_energy(self) -> float:
        """Closed-loop energy drawn from the DC bus [J]: the drives' inputs, inverter losses included."""
        return self.net_energy

    def summary(self) -> dict[str, object]:
        """The numbers of ``simulation.json`` for this run."""
        rms = float(np.sqrt(np.mean(self.tcp_error**2)))
        return {
            "payload_error": self.payload_error,
            "net_electrical_energy_J": self.net_energy,
            "predicted_net_electrical_energy_J": self.predicted_net_energy,
            "energy_difference_percent": change_percent(self.predicted_net_energy, self.net_energy),
            "copper_loss_J": float(self.copper_energy.sum()),
            "tcp_error_mm": {"rms": 1000.0 * rms, "max": 1000.0 * float(self.tcp_error.max())},
            "tcp_error_to_plan_mm": {
                "rms": 1000.0 * float(np.sqrt(np.mean(self.plan_error**2))),
                "max": 1000.0 * float(self.plan_error.max()),
            },
            "current_limit_fraction": float(self.current_limit_fraction.max()),
            "voltage_limit_fraction": float(self.voltage_limit_fraction.max()),
            "actuators": {
                name: {
                    "net_electrical_energy_J": float(self.cumulative_energy[-1, i]),
                    "predicted_net_electrical_energy_J": float(trapezoid(self.predicted_power[:, i], self.plan_time)),
                    "current_limit_fraction": float(self.current_limit_fraction[i]),
                    "voltage_limit_fraction": float(self.voltage_limit_fraction[i]),
                    "peak_current_A": float(np.abs(self.current_dq[:, i, 1]).max()),
                    "current_limit_A": float(self.current_limit[i]),
                    "peak_voltage_V": float(np.hypot(self.voltage_dq[:, i, 0], self.voltage_dq[:, i, 1]).max()),
                    "voltage_limit_V": float(self.voltage_limit[i]),
                }
                for i, name in enumerate(self.actuator_names)
            },
            "simulated_time_s": float(self.time[-1]),
            "wall_time_s": self.wall_time,
            "plant": self.plant,
            "dc_bus_energy_J": self.bus_energy,
            "dc_bus_energy_difference_percent": change_percent(self.predicted_net_energy, self.bus_energy),
            "inverter_loss_J": _total(self.inverter_energy),
            "motor_terminal_energy_J": _total(self.terminal_energy),
            "transmission_loss_J": _total(self.transmission_loss),
            "brake_coil_energy_J": _total(self.brake_coil_energy),
            "brake_carried_energy_J": _total(self.brake_carried),
            "drive_train_loss_J": 0.0 if self.drive_train_loss is None else float(self.drive_train_loss.sum()),
            "joint_friction_loss_J": self.friction_loss,
            "winding_temperature_C": None
            if self.winding_temperature is None
            else {name: float(t) for name, t in zip(self.actuator_names, self.winding_temperature, strict=True)},
            "cycles": list(self.cycles),
            "bandwidth_check": dict(self.bandwidth_check),
            "settle_time_s": self.settle_time_s,
            "predicted_net_electrical_energy_5ms_grid_J": self.resampled_prediction,
            "energy_difference_to_5ms_grid_percent": None
            if self.resampled_prediction is None
            else change_percent(self.resampled_prediction, self.net_energy),
        }


def _total(values: Array | None) -> float:
    """Sum over the drives [J] (0 when not logged)."""
    return 0.0 if values is None else float(np.sum(values))


def check_cycles(cycles: int) -> None:
    """A run's number of cycles: an integer >= 1 (a bool is not one); InvalidInputError naming ``cycles`` else."""
    if isinstance(cycles, bool) or not isinstance(cycles, int) or cycles < 1:
        raise InvalidInputError("cycles", cycles, "must be an integer >= 1")


def run_closed_loop(
    plan: DesignPlan,
    payload_error: float = 0.0,
    gains: CascadeGains | None = None,
    progress: Callable[[int, int], None] | None = None,
    plant: Plant | None = None,
    cycles: int = 1,
) -> tuple[ClosedLoopRun, CranePhysics]:
    """Simulate ``cycles`` cycles of a design's plan under the cascade controller; return the last log and the Physics.

    The Physics is returned at the end of the cycle (for rendering the logged ``qpos``); call its
    ``free()`` when done with it. ``gains`` None: the design rules for the plant (module docstring).
    """
    check_cycles(cycles)
    env = make_environment(plan, payload_error=payload_error, plant=plant)
    design = design_loop(plan, env.task.motion, plant)
    design = replace(design, gains=gains or design.gains)
    drives = DriveArrays.from_params(plan.emlas)
    run = run_environment(env, design, drives, plan.design, payload_error, plan, progress, plant, cycles)
    return replace(run, resampled_prediction=resampled_prediction(plan, env.task.motion), task=plan.task), env.physics


def run_environment(
    env: control.Environment,
    design: LoopDesign,
    drives: DriveArrays,
    name: str,
    payload_error: float,
    plan: PlanLike,
    progress: Callable[[int, int], None] | None = None,
    plant: Plant | None = None,
    cycles: int = 1,
    actuator_names: tuple[str, ...] = ACTUATOR_NAMES,
) -> ClosedLoopRun:
    """``cycles`` cycles of a prepared environment under the cascade of ``design`` (the crane's or a machine's).

    ``drives`` is the controller's model of the drives, ``plan`` what the log compares against (its
    ``time``, ``predicted_electrical_power`` and ``predicted_net_energy``).
    """
    physics: CranePhysics = env.physics
    task = env.task
    gains = design.gains
    controller = CascadeController(task.motion, drives, gains, design.stiffness, design.load_mass)
    steps = round(task.motion.time[-1] / env.control_timestep())
    history: list[dict[str, object]] = []
    for cycle in range(cycles):
        if cycle > 0 and physics.thermal is not None:
            physics.thermal.rest()
            physics.drives.drives = replace(physics.drives.drives, resistance=physics.thermal.resistance())
        log = _one_cycle(env, physics, controller, steps, progress)
        bus = float(physics.energy.sum())
        temperature = None if physics.thermal is None else physics.thermal.temperature.copy()
        history.append(
            {
                "cycle": cycle + 1,
                "dc_bus_energy_J": bus,
                "winding_temperature_C": None if temperature is None else [float(t) for t in temperature],
            }
        )
    time, error, plan_error, current, voltage, energy, qpos, wall = log
    n = len(time)
    dt = np.diff(time)
    power = np.vstack([np.diff(energy, axis=0) / dt[:, None], np.zeros((1, energy.shape[1]))])
    power[-1] = power[-2]
    return ClosedLoopRun(
        design=name,
        payload_error=payload_error,
        time=time,
        tcp_error=error,
        plan_error=plan_error,
        current_dq=current,
        voltage_dq=voltage,
        electrical_power=power,
        cumulative_energy=energy,
        plan_time=plan.time - plan.time[0],
        predicted_power=plan.predicted_electrical_power,
        predicted_net_energy=plan.predicted_net_energy,
        current_limit=physics.drives.drives.current_limit,
        voltage_limit=physics.drives.drives.voltage_limit,
        current_limit_fraction=physics.current_limited_steps / max(physics.steps, 1),
        voltage_limit_fraction=physics.voltage_limited_steps / max(physics.steps, 1),
        copper_energy=physics.copper.copy(),
        qpos=qpos[:n],
        wall_time=wall,
        plant="ideal" if plant is None else plant.name,
        inverter_energy=physics.inverter.copy(),
        terminal_energy=physics.terminal.copy(),
        transmission_loss=physics.transmission_loss.copy(),
        brake_coil_energy=physics.brake_coil.copy(),
        brake_carried=physics.brake_carried.copy(),
        drive_train_loss=physics.drive_train_loss.copy(),
        friction_loss=float(physics.friction_loss),
        winding_temperature=None if physics.thermal is None else physics.thermal.temperature.copy(),
        cycles=tuple(history),
        gains=gains,
        lowest_resonance_hz=design.lowest_resonance_hz,
        bandwidth_check=design.check(),
        settle_time_s=round(controller.settle_time() / env.control_timestep()) * env.control_timestep(),
        actuator_names=actuator_names,
    )


def settled_start(env: control.Environment, controller: CascadeController) -> dm_env.TimeStep:
    """Reset, hold the plan's first pose under the controller until it has settled, restart the clock.

    A crane starts a cycle from standing under its loops, not from a loop switched on at the first
    sample: for :meth:`~hiab_sim.control.cascade.CascadeController.settle_time` (5 time constants of
    the cascade's slowest pole) the controller holds the first sample
    (:meth:`~hiab_sim.control.cascade.CascadeController.hold`), so its integrator carries what the
    feedforward misses of the plant's true static load; then the physics clock and the energy
    counters restart at zero and the cycle's first time step is returned. On a plant the planner
    models exactly, nothing moves during the hold. Without it a load heavier than planned sags at the
    start before the integrator catches up, the largest TCP error of a run at the bandwidth the
    structure allows (docs/plant.md).
    """
    physics: CranePhysics = env.physics
    task = env.task
    step = env.reset()
    controller.reset()
    dt = env.control_timestep()
    substeps = round(dt / physics.timestep())
    observation = step.observation
    physics.holding = True
    for _ in range(round(controller.settle_time() / dt)):
        task.before_step(controller.hold(observation, dt), physics)
        physics.step(substeps)
        task.after_step(physics)
        observation = task.get_observation(physics)
    physics.holding = False
    controller.settled = True
    physics.data.time = 0.0
    physics.reset_counters()
    return dm_env.restart(task.get_observation(physics))


def _one_cycle(
    env: control.Environment,
    physics: CranePhysics,
    controller: CascadeController,
    steps: int,
    progress: Callable[[int, int], None] | None,
) -> tuple[Array, Array, Array, Array, Array, Array, Array, float]:
    """One episode: (time, TCP error, error to the plan, currents, voltages, cumulative energy, qpos, wall time)."""
    task = env.task
    nq = physics.model.nq
    n_drives = len(physics.slide_dofs)
    time = np.empty(steps + 1)
    error = np.empty(steps + 1)
    plan_error = np.empty(steps + 1)
    current = np.empty((steps + 1, n_drives, 2))
    voltage = np.empty((steps + 1, n_drives, 2))
    energy = np.empty((steps + 1, n_drives))
    qpos = np.empty((steps + 1, nq))
    start = _time.perf_counter()
    step = settled_start(env, controller)
    k = 0
    while True:
        obs = step.observation
        time[k] = obs["time"][0]
        error[k] = np.linalg.norm(obs["tcp"] - obs["reference_tcp"])
        plan_error[k] = np.linalg.norm(obs["tcp"] - task.motion.planned_tcp[task.motion.index(time[k])])
        current[k], voltage[k] = obs["current_dq"], obs["voltage_dq"]
        energy[k] = physics.energy
        qpos[k] = obs["joint_position"]
        if step.last():
            break
        step = env.step(controller(step))
        k += 1
        if progress is not None:
            progress(k, steps)
    wall = _time.perf_counter() - start
    n = k + 1
    return time[:n], error[:n], plan_error[:n], current[:n], voltage[:n], energy[:n], qpos[:n], wall

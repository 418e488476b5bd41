"""One closed-loop cycle of a design: the cascade controller on the environment, logged and summarised.

Energies come from the drives' exact per-step integrals (:mod:`hiab_sim.emla.drive_sim`): the net
electrical energy is int 3/2 (v_d i_d + v_q i_q) dt over the cycle, summed over the drives (the DC
bus credits regeneration of one drive to the others). The predicted energy is the optimiser's number
for the design (``result.json``); the predicted power is the plan's P_elec on its fine grid.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.control.cascade import CascadeController, CascadeGains
from hiab_sim.emla.config import ACTUATOR_NAMES
from hiab_sim.env import make_environment
from hiab_sim.env.physics import CranePhysics
from hiab_sim.env.plan import DesignPlan

Array = NDArray[np.float64]


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
        cumulative_energy: int P_elec dt per drive up to each time [J].
        plan_time, predicted_power: The plan's fine grid [s] and P_elec per actuator there [W].
        predicted_net_energy: The optimiser's net electrical energy [J].
        current_limit, voltage_limit: I_max [A] and V_max = |v_dq| limit [V] per drive.
        current_limit_fraction, voltage_limit_fraction: Fraction of physics steps at each limit, per drive.
        copper_energy: int 3/2 R_s |i|^2 dt per drive [J].
        qpos: Joint positions at every control step, for rendering (N, nq).
        wall_time: Wall-clock seconds of the simulation loop.

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

    @property
    def net_energy(self) -> float:
        """Closed-loop net electrical energy of all drives [J]."""
        return float(self.cumulative_energy[-1].sum())

    def summary(self) -> dict[str, object]:
        """The numbers of ``simulation.json`` for this run."""
        rms = float(np.sqrt(np.mean(self.tcp_error**2)))
        return {
            "payload_error": self.payload_error,
            "net_electrical_energy_J": self.net_energy,
            "predicted_net_electrical_energy_J": self.predicted_net_energy,
            "energy_difference_percent": 100.0 * (self.net_energy / self.predicted_net_energy - 1.0),
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
                    "predicted_net_electrical_energy_J": float(_trapezoid(self.predicted_power[:, i], self.plan_time)),
                    "current_limit_fraction": float(self.current_limit_fraction[i]),
                    "voltage_limit_fraction": float(self.voltage_limit_fraction[i]),
                    "peak_current_A": float(np.abs(self.current_dq[:, i, 1]).max()),
                    "current_limit_A": float(self.current_limit[i]),
                    "peak_voltage_V": float(np.hypot(self.voltage_dq[:, i, 0], self.voltage_dq[:, i, 1]).max()),
                    "voltage_limit_V": float(self.voltage_limit[i]),
                }
                for i, name in enumerate(ACTUATOR_NAMES)
            },
            "simulated_time_s": float(self.time[-1]),
            "wall_time_s": self.wall_time,
        }


def _trapezoid(y: Array, t: Array) -> float:
    return float(0.5 * np.sum((y[1:] + y[:-1]) * np.diff(t)))


def run_closed_loop(
    plan: DesignPlan,
    payload_error: float = 0.0,
    gains: CascadeGains | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> tuple[ClosedLoopRun, CranePhysics]:
    """Simulate one cycle of a design's plan under the cascade controller; return the log and the Physics.

    The Physics is returned at the end of the cycle (for rendering the logged ``qpos``); call its
    ``free()`` when done with it.
    """
    env = make_environment(plan, payload_error=payload_error)
    physics: CranePhysics = env.physics
    task = env.task
    controller = CascadeController(task.motion, physics.drives.drives, gains)
    steps = round(task.motion.time[-1] / env.control_timestep())
    nq = physics.model.nq
    time = np.empty(steps + 1)
    error = np.empty(steps + 1)
    plan_error = np.empty(steps + 1)
    current = np.empty((steps + 1, 3, 2))
    voltage = np.empty((steps + 1, 3, 2))
    energy = np.empty((steps + 1, 3))
    qpos = np.empty((steps + 1, nq))
    start = _time.perf_counter()
    step = env.reset()
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
    dt = np.diff(time[:n])
    power = np.vstack([np.diff(energy[:n], axis=0) / dt[:, None], np.zeros((1, 3))])
    power[-1] = power[-2]
    plan = task.plan
    run = ClosedLoopRun(
        design=plan.design,
        payload_error=payload_error,
        time=time[:n],
        tcp_error=error[:n],
        plan_error=plan_error[:n],
        current_dq=current[:n],
        voltage_dq=voltage[:n],
        electrical_power=power,
        cumulative_energy=energy[:n],
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
    )
    return run, physics

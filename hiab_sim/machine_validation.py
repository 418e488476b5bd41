"""Cross-validation of a machine file's two inverse-dynamics paths, behind ``hiab-sim validate --machine``.

The generic Newton-Euler path (:mod:`hiab_sim.machine.dynamics.newton_euler`) against the MuJoCo
path (:mod:`hiab_sim.machine.dynamics.mujoco_path`), made by
:func:`hiab_sim.machine.dynamics.paths.make_machine_dynamics`, on random states within every joint's
working range (within what the chains reach: :func:`hiab_sim.machine_mjcf.working_ranges`), without
and with a TCP force. Per case, as for the crane (:mod:`hiab_sim.validation`):

* the maximum absolute force difference per actuator, relative to that actuator's peak |f| over the
  case (Newton-Euler is the reference), and the maximum actuator-velocity difference [m/s];
* the power balance of each path, ``sum_j f_j v_j + F_tcp . v_tcp - dE/dt`` relative to the peak of
  ``|sum f v + F_tcp . v_tcp|`` (the virtual-power statement of eq. ``dynamics``). E = T + U is the
  machine's mechanical energy from MuJoCo's ``mj_energyPos`` + ``mj_energyVel`` on the loop-consistent
  state (every body: cylinders, rods, rockers, couplers), and v_tcp the TCP velocity of the
  description's forward kinematics (:func:`hiab_sim.machine.kinematics.forward.forward_kinematics`);
  both are differentiated along the motion q(t + s) = q + dq s + ddq s^2 / 2 by the five-point
  stencil with step :data:`TIME_STEP`, so neither uses an inverse-dynamics path.

Positions uniform over the ranges (:data:`RANGE_MARGIN` inside the ends, where the stencils reach);
velocities ~ N(0, 0.3) rad/s or m/s; accelerations ~ N(0, 1) rad/s^2 or m/s^2,
as the crane's random states (:func:`hiab_sim.validation.random_states`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.checks import check_range
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine_mjcf import working_ranges
from hiab_sim.validation import Tolerances

#: Step of the five-point time stencils [s]: truncation O(s^4) and round-off eps E / s both < 1e-10 of the
#: peak power for these machines (E ~ 1e4 J, power ~ 1e3 W).
TIME_STEP = 1e-3
#: Default TCP force [N] in the world plane (x, y up): a 250 kg payload's weight, (0, -250 * 9.81), the
#: crane case file's ``payload_force``.
DEFAULT_TCP_FORCE = (0.0, -2452.0)
#: Distance the sampled positions keep from each working-range end [rad or m]: the stencils reach
#: 2 TIME_STEP |dq| + 2 TIME_STEP^2 |ddq| away, < 4e-3 for |dq| < 1.5 (five standard deviations of 0.3).
RANGE_MARGIN = 1e-2
_STENCIL = ((-2, 1.0), (-1, -8.0), (1, 8.0), (2, -1.0))  # f' ~ sum w f(t + k s) / (12 s)


@dataclass(frozen=True)
class MachineCaseResult:
    """One case's agreement; lists are per actuator (the machine's actuator order)."""

    name: str
    samples: int
    tcp_force: tuple[float, float]
    actuators: tuple[str, ...]
    peak_force: list[float]
    force_abs_error: list[float]
    force_rel_error: list[float]
    velocity_abs_error: list[float]
    balance_newton_euler: float
    balance_mujoco: float
    passed: bool

    def __post_init__(self) -> None:
        check_range(f"{self.name}.samples", self.samples, 1, integral=True)


def random_machine_states(machine: Machine, rng: np.random.Generator, n: int) -> tuple[Array, Array, Array]:
    """(q, dq, ddq), each (n, n_joints): uniform positions in the working ranges (:data:`RANGE_MARGIN` inside).

    The first two rows hold the range ends (alternating per joint), as the crane's random states.
    """
    ranges = np.array(working_ranges(machine)) + np.array([RANGE_MARGIN, -RANGE_MARGIN])
    fraction = rng.uniform(0.0, 1.0, (n, len(ranges)))
    if n >= 4:
        fraction[0], fraction[1] = np.arange(len(ranges)) % 2, 1 - np.arange(len(ranges)) % 2
    q = np.clip(
        ranges[:, 0] + fraction * (ranges[:, 1] - ranges[:, 0]), ranges[:, 0], ranges[:, 1]
    )  # no ulp past an end
    return q, rng.normal(0.0, 0.3, q.shape), rng.normal(0.0, 1.0, q.shape)


def _stencil(values: list[Array]) -> Array:
    return sum(w * v for (_, w), v in zip(_STENCIL, values, strict=True)) / (12.0 * TIME_STEP)  # type: ignore[return-value]


def energy_rate(dynamics: MujocoMachineDynamics, q: Array, dq: Array, ddq: Array) -> Array:
    """dE/dt (T,) [W] of the mechanical energy T + U along each sample's motion (module docstring)."""
    import mujoco

    model, data = dynamics.model, dynamics.data
    energies = []
    for k, _ in _STENCIL:
        s = k * TIME_STEP
        qpos, qvel, _ = dynamics.state(q + dq * s + 0.5 * ddq * s * s, dq + ddq * s, ddq)
        e = np.empty(len(q))
        for i in range(len(q)):
            data.qpos[:], data.qvel[:] = qpos[i], qvel[i]
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            mujoco.mj_energyPos(model, data)
            mujoco.mj_crb(model, data)  # the mass matrix mj_energyVel needs
            mujoco.mj_energyVel(model, data)
            e[i] = data.energy[0] + data.energy[1]
        energies.append(e)
    return _stencil(energies)


def tcp_velocity(machine: Machine, q: Array, dq: Array, ddq: Array) -> Array:
    """TCP velocity (T, 2) [m/s] in the world plane from the forward kinematics along the motion."""
    points = []
    for k, _ in _STENCIL:
        s = k * TIME_STEP
        points.append(forward_kinematics(machine, q + dq * s + 0.5 * ddq * s * s).tcp_position[:, :2])
    return _stencil(points)


def run_machine_case(
    machine: Machine, name: str, samples: int, seed: int, tcp_force: tuple[float, float], tolerances: Tolerances
) -> MachineCaseResult:
    """Both paths on ``samples`` random states (seed ``seed``) with ``tcp_force`` [N]; errors and balances."""
    q, dq, ddq = random_machine_states(machine, np.random.default_rng(seed), samples)
    newton_euler = make_machine_dynamics(machine, path="newton_euler")
    mujoco_id = make_machine_dynamics(machine, path="mujoco")
    if not isinstance(mujoco_id, MujocoMachineDynamics):
        raise AssertionError("the mujoco path is MujocoMachineDynamics")
    force = np.asarray(tcp_force, dtype=float)
    ne, mj = newton_euler(q, dq, ddq, force), mujoco_id(q, dq, ddq, force)
    rate = energy_rate(mujoco_id, q, dq, ddq)
    external = tcp_velocity(machine, q, dq, ddq) @ force
    power_ne = np.sum(ne.force * ne.velocity, axis=1) + external
    power_mj = np.sum(mj.force * mj.velocity, axis=1) + external
    norm = max(float(np.max(np.abs(power_ne))), np.finfo(float).tiny)
    peak = np.max(np.abs(ne.force), axis=0)
    force_abs = np.max(np.abs(mj.force - ne.force), axis=0)
    force_rel = force_abs / np.maximum(peak, np.finfo(float).tiny)
    velocity_abs = np.max(np.abs(mj.velocity - ne.velocity), axis=0)
    balance_ne = float(np.max(np.abs(power_ne - rate))) / norm
    balance_mj = float(np.max(np.abs(power_mj - rate))) / norm
    passed = bool(
        np.all(force_rel <= tolerances.force_relative)
        and np.all(velocity_abs <= tolerances.velocity_absolute)
        and balance_ne <= tolerances.balance_relative
        and balance_mj <= tolerances.balance_relative
    )
    return MachineCaseResult(
        name=name,
        samples=samples,
        tcp_force=(float(force[0]), float(force[1])),
        actuators=tuple(machine.actuator_names),
        peak_force=peak.tolist(),
        force_abs_error=force_abs.tolist(),
        force_rel_error=force_rel.tolist(),
        velocity_abs_error=velocity_abs.tolist(),
        balance_newton_euler=balance_ne,
        balance_mujoco=balance_mj,
        passed=passed,
    )


def machine_cases(
    machine: Machine, samples: int, tcp_force: tuple[float, float], tolerances: Tolerances, seed: int = 0
) -> list[MachineCaseResult]:
    """The two cases: random states without a TCP force, and the same states with ``tcp_force`` [N]."""
    return [
        run_machine_case(machine, "random_states", samples, seed, (0.0, 0.0), tolerances),
        run_machine_case(machine, "random_states+tcp_force", samples, seed, tcp_force, tolerances),
    ]


def machine_table(machine: Machine, results: list[MachineCaseResult], tolerances: Tolerances) -> str:
    """The markdown table of the machine's cases, with what each column means and the tolerances."""
    lines = [
        f"Machine: {machine.name} (actuators {', '.join(machine.actuator_names)})",
        "",
        "| case | samples | TCP force [N] | max abs force error [N] | max rel force error | "
        "max abs velocity error [m/s] | balance (Newton-Euler) | balance (MuJoCo) | pass |",
        "|---|---:|---|---:|---:|---:|---:|---:|:---:|",
    ]
    for r in results:
        lines.append(
            f"| {r.name} | {r.samples} | ({r.tcp_force[0]:g}, {r.tcp_force[1]:g}) | {max(r.force_abs_error):.2e} | "
            f"{max(r.force_rel_error):.2e} | {max(r.velocity_abs_error):.2e} | {r.balance_newton_euler:.2e} (power) | "
            f"{r.balance_mujoco:.2e} | {'yes' if r.passed else 'NO'} |"
        )
    lines.append("")
    lines.append(
        "Errors are MuJoCo minus Newton-Euler. Balance: max |sum f v + F_tcp . v_tcp - dE/dt| over the peak power, "
        "E = T + U of every body (MuJoCo's energy on the loop-consistent state), v_tcp from the forward kinematics, "
        f"both differentiated in time by five-point stencils ({TIME_STEP:g} s). Tolerances: force errors <= "
        f"{tolerances.force_relative:g} of each actuator's peak |f|, velocity error <= "
        f"{tolerances.velocity_absolute:g} m/s, balances <= {tolerances.balance_relative:g}."
    )
    return "\n".join(lines) + "\n"

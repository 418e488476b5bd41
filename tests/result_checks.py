"""Independent re-evaluation of a result folder's designs (shared test helper, not a test module).

The optimiser's report evaluates each design through :class:`TaskProblem` on the ID path of
the run. Here a design is re-evaluated from what the folder holds, without the problem: the link
lengths of ``result.json``, the joint samples of ``trajectory.npz`` (fine grid), the *other* ID
path called directly, the EMLA electrical power, and the quadratures written out below.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla import EmlaSet, electrical_power
from hiab_sim.emla.duty_energy import DutyOptions, drive_duty
from hiab_sim.results.schema import Result

DESIGNS = ("initial", "optimal")


def other_path(path: str) -> str:
    """The ID path the run did not use."""
    return {"mujoco": "analytic", "analytic": "mujoco"}[path]


def design_energy(
    crane: Any,
    emlas: EmlaSet,
    lengths: Any,
    time: np.ndarray,
    joints: JointSamples,
    path: str,
    payload_kg: float,
    duty: DutyOptions | None = None,
) -> tuple[float, float]:
    """(net electrical energy [J] by the trapezoid rule, eq. costf2 cost 1/2 Dt sum_k (sum_i P_i)^2 [W^2 s]).

    With ``duty`` (the study's duty model) the drive powers are those at the coupled winding temperature.
    """
    tcp_force = None if payload_kg == 0.0 else np.array([0.0, -payload_kg * crane.gravity, 0.0])
    if path == "mujoco":
        act = MujocoInverseDynamics(crane, lengths)(joints, tcp_force=tcp_force)
    else:
        act = analytic_inverse_dynamics(crane, lengths, joints, tcp_force=tcp_force)
    if duty is not None:
        power: np.ndarray = sum(  # type: ignore[assignment]
            drive_duty(p, time, act.force[:, i], act.velocity[:, i], act.acceleration[:, i], duty).power
            for i, p in enumerate(emlas)
        )
    else:
        power = sum(  # type: ignore[assignment]
            electrical_power(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
            for i, p in enumerate(emlas)
        )
    step = np.diff(time)
    assert np.allclose(step, step[0], rtol=1e-9), "the fine grid is uniform"
    net = float(np.sum(0.5 * (power[1:] + power[:-1]) * step))
    cost = 0.5 * float(step[0]) * float(np.sum(power**2))
    return net, cost


def four_designs(
    folder: Path, result: Result, crane: Any, emlas: EmlaSet, duty: DutyOptions | None = None
) -> dict[tuple[str, str], tuple[float, float]]:
    """(net energy, cost) of {initial, optimal} lengths x {initial, optimal} joint trajectory, by the other path."""
    data = np.load(folder / "trajectory.npz")
    time = data["time"]
    path = other_path(result.solver.id_path)
    lengths = {"initial": result.initial.lengths, "optimal": result.optimal.lengths}
    out = {}
    for trajectory in DESIGNS:
        joints = JointSamples(*(data[f"{trajectory}_{kind}"] for kind in ("position", "velocity", "acceleration")))
        for xi in DESIGNS:
            out[xi, trajectory] = design_energy(
                crane, emlas, lengths[xi], time, joints, path, result.settings.payload_kg, duty
            )
    return out

"""A short synthetic plan for the closed-loop tests: rest-to-rest quintic moves of the default crane.

The plan's predicted power is the steady-state EMLA model (:func:`hiab_sim.emla.electrical_power`) on
the analytic inverse dynamics, and its TCP reference is the source's trigonometric forward
kinematics: both independent of the MuJoCo forward simulation and the time-domain drives.
"""

from __future__ import annotations

import numpy as np

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.kinematics import forward_kinematics
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla import electrical_power, load_emla_set
from hiab_sim.env.plan import DesignPlan


def synthetic_plan(
    crane: Crane, lengths: LinkLengths | None = None, duration: float = 1.5, emla: str = "paper"
) -> DesignPlan:
    """Θ1 0.55 -> 0.65 rad, Θ2 -1.35 -> -1.25 rad, xt2 0.4 -> 0.5 m, quintic rest to rest over ``duration``.

    ``emla``: the EMLA set (``paper``: the lossless drive; ``default``: emla_xs031.yaml's real drive).
    """
    lengths = crane.default_lengths if lengths is None else lengths
    time = np.linspace(0.0, duration, 61)
    tau = time / duration
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    ds = (30 * tau**2 - 60 * tau**3 + 30 * tau**4) / duration
    dds = (60 * tau - 180 * tau**2 + 120 * tau**3) / duration**2
    start, delta = np.array([0.55, -1.35, 0.4]), np.array([0.1, 0.1, 0.1])
    joints = JointSamples(start + np.outer(s, delta), np.outer(ds, delta), np.outer(dds, delta))
    actuators = analytic_inverse_dynamics(crane, lengths, joints)
    emlas = load_emla_set(None if emla == "default" else emla)
    power = np.stack(
        [
            electrical_power(p, actuators.force[:, i], actuators.velocity[:, i], actuators.acceleration[:, i])
            for i, p in enumerate(emlas)
        ],
        axis=1,
    )
    total = power.sum(axis=1)
    tcp = forward_kinematics(crane, lengths, *joints.position.T).position["tcp"]
    return DesignPlan(
        design="optimal",
        crane=crane,
        emlas=emlas,
        lengths=lengths,
        time=time,
        position=joints.position,
        velocity=joints.velocity,
        acceleration=joints.acceleration,
        reference_tcp=tcp,
        predicted_electrical_power=power,
        predicted_net_energy=float(0.5 * np.sum((total[1:] + total[:-1]) * np.diff(time))),
        payload=0.0,
    )

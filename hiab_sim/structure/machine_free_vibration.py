"""Free vibration of a machine file's spring-mounted MuJoCo model: the independent check of its frequencies.

As :mod:`hiab_sim.structure.free_vibration` for the crane, on the generic machine MJCF
(:func:`hiab_sim.machine.dynamics.mjcf_build.build_machine_spec`): every actuated joint (a chain's
rod slide, a direct chain's prismatic joint) gets a linear spring of its drive train's stiffness
k_a at the pose (joint ``stiffness``) with ``springref`` = x_a + f_a / k_a, so that it pushes with
the static actuator force f_a there (MuJoCo's joint spring force is -k (x - springref)) and the
pose is an equilibrium. The loops are MuJoCo's soft ``connect`` equalities with ``solref`` =
(2 dt, 1), whose own frequency ~1 / (2 dt) rad/s lies decades above the machine's.

Started at the equilibrium with a small loop-consistent velocity along one mode shape (qvel = Z phi a,
Z's columns the full-coordinate rates of unit independent rates, from the MuJoCo path's own loop
solution), the model runs freely (RK4); the modal coordinate y = phi^T M (q_i - q_i0) is recorded
and its frequency is the peak of its FFT (:func:`hiab_sim.structure.free_vibration.spectrum_peak_Hz`).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.mjcf_build import build_machine_spec
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.structure.free_vibration import LOWEST_MODE, FreeVibration, modal_peak_Hz, spring_mounted_model
from hiab_sim.structure.machine_modes import actuator_jacobian, machine_natural_frequencies, mass_matrix, static_forces


def machine_free_vibration_frequency(
    machine: Machine,
    emlas: EmlaSet,
    pose: ArrayLike,
    run: FreeVibration = LOWEST_MODE,
) -> tuple[float, float]:
    """(simulated, eigenvalue) frequency [Hz] of mode ``run.mode`` at a static pose (n,) (module docstring).

    ``machine`` carries the design (``Machine.with_design``); the eigenvalue problem is solved on
    its MuJoCo path, the simulation on its spring-mounted MJCF.
    """
    mode, timestep = run.mode, run.timestep
    q0 = np.asarray(pose, dtype=float).reshape(1, -1)
    inverse = MujocoMachineDynamics(machine)
    modes = machine_natural_frequencies(machine, inverse, emlas, q0)
    phi = modes.shape[0][:, mode]
    omega = 2.0 * math.pi * modes.frequency_Hz[0, mode]
    force = static_forces(inverse, q0)[0]
    n = q0.shape[1]
    qpos, _, _ = inverse.state(q0, np.zeros_like(q0), np.zeros_like(q0))
    Z = np.stack(
        [inverse.state(q0, np.eye(n)[i : i + 1], np.zeros_like(q0))[1][0] for i in range(n)], axis=1
    )  # (nv, n): full rates per unit independent rate

    # the modes' actuator columns are in chain order, the spec's actuators named after the chains
    chains = [chain.name for chain in machine.chains]
    spec = build_machine_spec(machine)
    model = spring_mounted_model(spec, timestep, chains, modes.stiffness_N_per_m[0], force, inverse.model, qpos[0])
    data = mujoco.MjData(model)
    data.qpos[:] = qpos[0]
    rate = omega * run.stroke_amplitude / float(np.max(np.abs(modes.actuator_shape[0][:, mode])))
    data.qvel[:] = Z @ (phi * rate)
    mass = mass_matrix(inverse, q0, actuator_jacobian(inverse, q0))[0]
    weights = phi @ mass
    tree = inverse.tree
    independent = np.array([model.joint(tree.bodies[b].joint).qposadr[0] for b in tree.independent])
    simulated = modal_peak_Hz(model, data, weights, independent, q0[0], omega, timestep, run.periods)
    return simulated, float(modes.frequency_Hz[0, mode])

"""Free vibration of the spring-mounted MuJoCo model: the independent check of the natural frequencies.

The MuJoCo model of the crane (:func:`hiab_sim.model.mjcf.build_spec`) gets, on every actuated
slide, a linear spring of the drive train's stiffness k_a at the pose (joint ``stiffness``) whose
``springref`` = x_a + f_a / k_a makes the spring push with the static actuator force f_a there,
so the pose is an equilibrium (MuJoCo's joint spring force is -k (x - springref)). The loops stay
MuJoCo's soft ``connect`` equalities with ``solref`` = (2 dt, 1): their own frequency ~1 / (2 dt)
rad/s lies three decades above the crane's, so they do not soften it measurably.

Started at the equilibrium with a small velocity along one mode shape (loop-consistent: qvel = Z
phi a, :func:`hiab_sim.structure.natural_frequency_mujoco.loop_projection`), the model is
integrated freely (RK4); the modal coordinate y = phi^T M (q_i - q_i0) (M-orthogonality filters
the other modes) is recorded, and its frequency is the peak of its FFT (Hann window, zero-padded,
parabolic interpolation of the log magnitude around the peak bin).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.names import JOINT_NAMES
from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla.config import EmlaSet
from hiab_sim.model.mjcf import build_spec
from hiab_sim.structure.natural_frequency import natural_frequencies, static_forces
from hiab_sim.structure.natural_frequency_mujoco import loop_projection, mujoco_mass_matrix


@dataclass(frozen=True)
class FreeVibration:
    """How one mode's free vibration is simulated, by the crane's check and by a machine file's.

    Attributes:
        mode: Index of the mode, 0 the lowest [-].
        timestep: MuJoCo step [s] (RK4).
        periods: Length of the record in periods of the mode [-].
        stroke_amplitude: Largest actuator stroke amplitude of the start velocity along the mode [m].

    """

    mode: int = 0
    timestep: float = 1e-4
    periods: float = 30.0
    stroke_amplitude: float = 1e-5


#: The lowest mode, as both checks simulate it unless told otherwise.
LOWEST_MODE = FreeVibration()


def spectrum_peak_Hz(signal: ArrayLike, sample_time: float, pad: int = 64) -> float:
    """Frequency [Hz] of the largest peak of a signal's spectrum (Hann window, zero-padded, parabolic)."""
    y = np.asarray(signal, dtype=float)
    y = (y - y.mean()) * np.hanning(y.size)
    n = pad * y.size
    magnitude = np.abs(np.fft.rfft(y, n))
    k = int(np.argmax(magnitude[1:-1])) + 1
    a, b, c = np.log(magnitude[k - 1 : k + 2])
    shift = 0.5 * (a - c) / (a - 2.0 * b + c)
    return float((k + shift) / (n * sample_time))


def spring_mounted_model(
    spec: mujoco.MjSpec,
    timestep: float,
    actuators: Sequence[str],
    stiffness: Array,
    force: Array,
    id_model: mujoco.MjModel,
    qpos: Array,
) -> mujoco.MjModel:
    """The spec with a spring of stiffness k_a [N/m] on each named actuator's joint, pushing f_a [N] at ``qpos``.

    RK4 at ``timestep`` [s], the loops' ``solref`` (2 dt, 1), and per actuator (in the columns' order of
    ``stiffness`` and ``force``) ``springref`` = x_a + f_a / k_a with x_a its joint's coordinate in
    ``qpos`` of ``id_model`` (the model the state was solved on; module docstring).
    """
    spec.option.timestep = timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    for equality in spec.equalities:
        equality.solref = [2.0 * timestep, 1.0]
    targets = {a.name: a.target for a in spec.actuators}
    for k, name in enumerate(actuators):
        joint = spec.joint(targets[name])
        k_a = float(stiffness[k])
        stroke = float(qpos[id_model.joint(targets[name]).qposadr[0]])
        joint.stiffness = [k_a, 0.0, 0.0]
        joint.springref = stroke + float(force[k]) / k_a
    return spec.compile()


def modal_peak_Hz(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    weights: Array,
    independent: Array,
    q0: Array,
    omega: float,
    timestep: float,
    periods: float,
) -> float:
    """Run the released model freely; the FFT peak [Hz] of the modal coordinate weights . (q_i - q0)."""
    period = 2.0 * math.pi / omega
    record_every = max(1, int(period / (40.0 * timestep)))
    samples = int(periods * period / (record_every * timestep))
    y = np.empty(samples)
    for i in range(samples):
        y[i] = weights @ (data.qpos[independent] - q0)
        mujoco.mj_step(model, data, nstep=record_every)
    return spectrum_peak_Hz(y, record_every * timestep)


def free_vibration_frequency(
    crane: Crane,
    emlas: EmlaSet,
    lengths: LinkLengths,
    pose: ArrayLike,
    run: FreeVibration = LOWEST_MODE,
    payload_kg: float = 0.0,
) -> float:
    """Frequency [Hz] of mode ``run.mode`` at a static pose (n,), from a free-vibration simulation (module docstring).

    ``payload_kg``: a point mass added to the MuJoCo model at the TCP site (its weight and inertia
    then come from MuJoCo); the eigenvalue problem gets it as ``payload_kg`` and a TCP force.
    """
    mode, timestep = run.mode, run.timestep
    q0 = np.asarray(pose, dtype=float).reshape(1, -1)
    weight = np.array([0.0, -payload_kg * crane.gravity, 0.0]) if payload_kg > 0.0 else None
    modes = natural_frequencies(crane, emlas, lengths, q0, weight, payload_kg=payload_kg)
    phi = modes.shape[0][:, mode]
    omega = 2.0 * math.pi * modes.frequency_Hz[0, mode]
    force = static_forces(crane, lengths, q0, weight)[0]

    spec = build_spec(crane, lengths)
    if payload_kg > 0.0:
        tcp = spec.site("tcp")
        load = tcp.parent.add_body(name="payload", pos=list(tcp.pos))
        load.explicitinertial = True
        load.mass = payload_kg
        load.ipos = [0.0, 0.0, 0.0]
        load.inertia = [1e-9, 1e-9, 1e-9]
    inverse = MujocoInverseDynamics(crane, lengths)
    qpos, _, _ = inverse.state(JointSamples.at_rest(q0))
    model = spring_mounted_model(
        spec, timestep, modes.actuator_names, modes.stiffness_N_per_m[0], force, inverse.model, qpos[0]
    )
    data = mujoco.MjData(model)
    data.qpos[:] = qpos[0]
    mujoco.mj_fwdPosition(model, data)
    Z = loop_projection(model, data, [c.name for c in crane.chains])
    rate = omega * run.stroke_amplitude / float(np.max(np.abs(modes.actuator_shape[0][:, mode])))
    data.qvel[:] = Z @ (phi * rate)
    mass, _ = mujoco_mass_matrix(crane, lengths, q0)
    weights = phi @ mass[0]  # the crane's M without the payload still picks this mode out
    independent = np.array([model.joint(name).qposadr[0] for name in JOINT_NAMES])
    return modal_peak_Hz(model, data, weights, independent, q0[0], omega, timestep, run.periods)

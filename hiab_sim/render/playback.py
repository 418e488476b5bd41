"""Playback of an optimisation result: read the result folder, build the states, render the video.

A result folder (written by ``hiab-sim optimize``) holds ``result.json`` with the crane
(``crane``: preset name or YAML path), the link lengths of the ``initial`` and ``optimal``
designs and, where the study has a battery model, their battery energy (``energy``), and
``trajectory.npz`` with ``time`` (K,), ``reference_tcp`` (K, 3) in the source world {W} (y up),
per design d ``{d}_position``, ``{d}_velocity``, ``{d}_acceleration`` (K, 3) of (theta1, theta2,
xt2) and, in results that have them, ``{d}_battery_power`` (K,), the battery's power over the cycle
(the overlay's cumulative battery energy), and ``payload_mass`` (K,), the payload held at the TCP.

Two playback modes:

- ``kinematic``: the planned states, the closed chains solved by the MuJoCo inverse-dynamics
  module (:meth:`~hiab_sim.dynamics.mujoco_id.MujocoInverseDynamics.state`).
- ``simulate``: a forward simulation of the MJCF model driven by the actuator forces that the
  MuJoCo inverse dynamics computes for the planned motion (:mod:`hiab_sim.dynamics.replay`), so
  the video shows that those forces really move the crane along the reference.

Both are resampled to the video's frame rate, in real time.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.results.playback_view import PlaybackView
from hiab_sim.results.read import open_run, result_crane
from hiab_sim.results.trajectory_file import Trajectory, battery_powers

Mode = Literal["kinematic", "simulate"]
MODES: tuple[str, ...] = ("kinematic", "simulate")
DESIGNS = ("initial", "optimal")
#: Spacing of the force samples of a simulated playback [s]: the replay's integrator step.
SIMULATION_STEP = 1e-3


@dataclass(frozen=True)
class DesignMotion:
    """One design of a result: its link lengths and planned joint samples at ``PlaybackData.time``."""

    name: str
    lengths: LinkLengths
    joints: JointSamples


@dataclass(frozen=True)
class PlaybackData:
    """What a playback needs from a result folder."""

    crane: Crane
    time: Array  # (K,) [s], increasing
    reference_tcp: Array  # (K, 3) in the source world {W} [m]
    designs: tuple[DesignMotion, ...]
    #: Payload mass carried at the TCP at ``time`` (K,) [kg], 0 while not held; None: the result has no schedule.
    payload_mass: Array | None = None
    #: Each design's battery energy of ``result.json`` [J]; None: the result has no battery model.
    battery_energy_J: dict[str, float] | None = None
    #: The period that battery energy covers: "cycle", or "duty period" with the study's duty model (cycle + rest).
    battery_period: str = "cycle"
    #: Each design's battery power over the cycle at ``time`` (K,) [W] (``<design>_battery_power``); None: none.
    battery_power: dict[str, Array] | None = None


def load_playback(result_dir: str | Path) -> PlaybackData:
    """Read ``result.json`` and ``trajectory.npz`` of a result folder.

    Raises:
        ConfigError: the folder or one of its files is missing or corrupt (not JSON / NPZ,
            missing keys, wrong shapes).

    """
    run = open_run(result_dir, PlaybackView)
    view, trajectory = run.result, run.trajectory
    crane = result_crane(run.folder, view.crane)
    time = trajectory.time()
    reference = _columns(trajectory, trajectory.get("reference_tcp"), "reference_tcp")
    designs = []
    for name in DESIGNS:
        joints = JointSamples(
            *(_columns(trajectory, trajectory.design(name, kind), f"{name}_{kind}") for kind in _KINDS)
        )
        designs.append(DesignMotion(name, getattr(view, name).lengths, joints))
    payload = trajectory.get("payload_mass") if "payload_mass" in trajectory.arrays else None
    if payload is not None and (payload.ndim != 1 or np.any(payload < 0.0)):
        raise ConfigError(f"{trajectory.path}: array 'payload_mass' must be (K,) masses >= 0 kg")
    battery, period = None, "cycle"
    if view.energy is not None:
        battery = {name: getattr(view.energy, name).battery_energy_J for name in DESIGNS}
        period = view.energy.period
    return PlaybackData(crane, time, reference, tuple(designs), payload, battery, period, battery_powers(trajectory))


def _columns(trajectory: Trajectory, value: Array, key: str) -> Array:
    """The renderer draws the XS 031's three joints and a 3-column TCP: other shapes are refused by name."""
    if value.ndim != 2 or value.shape[1] != 3:
        raise ConfigError(f"{trajectory.path}: array '{key}' has shape {value.shape}, expected (K, 3) numbers")
    return value


_KINDS = ("position", "velocity", "acceleration")


def frame_times(time: Array, fps: float) -> Array:
    """Frame instants t0, t0 + 1/fps, ... up to the last sample [s]: real-time playback."""
    if not fps > 0:
        raise InvalidInputError("fps", fps, "must be > 0", "1/s")
    count = int(np.floor((time[-1] - time[0]) * fps + 1e-9)) + 1
    return time[0] + np.arange(count) / fps


def resample(time: Array, values: Array, at: Array) -> Array:
    """Linear interpolation of ``values`` (K, n) sampled at ``time`` onto the instants ``at``."""
    return np.stack([np.interp(at, time, column) for column in np.asarray(values).T], axis=1)


def planned_qpos(crane: Crane, lengths: LinkLengths, position: Array) -> Array:
    """Loop-consistent qpos (N, nq) of the MJCF model for joint positions (theta1, theta2, xt2) (N, 3).

    The closed chains are solved by :meth:`MujocoInverseDynamics.state
    <hiab_sim.dynamics.mujoco_id.MujocoInverseDynamics.state>`, which also checks the joint ranges.
    """
    from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics

    qpos, _, _ = MujocoInverseDynamics(crane, lengths).state(JointSamples.at_rest(position))
    return qpos


def densify(time: Array, joints: JointSamples, step: float = SIMULATION_STEP) -> tuple[Array, JointSamples]:
    """Joint samples on a grid of spacing <= ``step`` [s]: quintic Hermite through (p, v, a) of each sample.

    The interpolant matches position, velocity and acceleration at every given sample, so the
    dense samples stay consistent (v = dp/dt, a = dv/dt) between them.
    """
    from scipy.interpolate import BPoly

    count = int(np.ceil((time[-1] - time[0]) / step - 1e-9)) + 1
    fine = np.linspace(time[0], time[-1], max(count, len(time)))
    columns: list[list[Array]] = [[], [], []]
    for j in range(3):
        knots = np.stack([joints.position[:, j], joints.velocity[:, j], joints.acceleration[:, j]], axis=1)
        poly = BPoly.from_derivatives(time, knots)
        for order in range(3):
            columns[order].append(poly.derivative(order)(fine) if order else poly(fine))
    position, velocity, acceleration = (np.stack(c, axis=1) for c in columns)
    return fine, JointSamples(position, velocity, acceleration)


def simulated_qpos(crane: Crane, lengths: LinkLengths, time: Array, joints: JointSamples) -> tuple[Array, Array]:
    """A forward simulation driven by the inverse-dynamics forces: (time (T,), qpos (T, nq)).

    The planned joints are first densified to the simulation step (:func:`densify`): forces are
    interpolated linearly between their samples, and from samples tens of milliseconds apart
    that error alone lets the open-loop replay drift off the plan. The forces f_x of
    :class:`~hiab_sim.dynamics.mujoco_id.MujocoInverseDynamics` then drive the model's motors
    from the first planned state, without feedback (:func:`hiab_sim.dynamics.replay.replay`).
    """
    from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
    from hiab_sim.dynamics.replay import replay

    fine, dense = densify(time, joints)
    forces = MujocoInverseDynamics(crane, lengths)(dense).force
    return fine, replay(crane, lengths, fine, dense, forces).qpos

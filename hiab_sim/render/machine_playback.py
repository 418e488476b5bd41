"""Playback of a machine file's result: both designs' joint samples replayed in the machine's MJCF.

A machine file's result folder (``hiab-sim optimize`` on a study with ``machine:``) holds
``result.json`` whose designs are :class:`~hiab_sim.machine.design.MachineDesign` values and
``trajectory.npz`` with ``time`` (K,), ``reference_tcp`` (K, 3) in the description's world (y up),
per design d ``{d}_position`` (K, n_joints) in ``machine.joint_names`` order and, where present,
``{d}_electrical_power`` (K, n_actuators) [W] and ``payload_mass`` (K,) [kg].

Each design's model is the machine's MJCF at that design (:func:`hiab_sim.machine_mjcf.machine_mjcf`:
the generic builder, posed and framed); every joint of it, the chains' cylinders, rods, rockers and
couplers included, is set per frame from the loop closure polished on MuJoCo's own pins
(:meth:`~hiab_sim.machine.dynamics.mujoco_path.MujocoMachineDynamics.state`), so the connect
equalities hold to |C| < 1e-13 m in every frame. Frames, captions, the reference path, the TCP trails
and the energy line are the crane's (:class:`~hiab_sim.render.frames.PlaybackRenderer`,
:func:`~hiab_sim.render.video.energy_notes`); the machine is dressed from its description
(:mod:`hiab_sim.render.dress_machine`), standing on the ground level of the soil its study's tasks
cut (``tasks[].soil.ground``, read from the study file the result names, when that file is there).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.errors import ConfigError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import MachineDesign
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine_mjcf import machine_mjcf, posed_qpos, result_design
from hiab_sim.model.mjcf import source_to_world
from hiab_sim.results.read import RESULT_FILE, read_result, result_machine
from hiab_sim.results.trajectory_file import battery_powers, read_trajectory

DESIGNS = ("initial", "optimal")


@dataclass(frozen=True)
class MachineMotion:
    """One design of a machine result: its decision-variable values [m] and joint positions (K, n_joints)."""

    name: str
    design: Array
    position: Array
    power: Array | None  # net electrical power summed over the actuators (K,) [W]; None when not stored


@dataclass(frozen=True)
class MachinePlayback:
    """What a machine result's playback needs."""

    machine: Machine
    time: Array  # (K,) [s], increasing
    reference_tcp: Array  # (K, 3) in the description's world [m]
    designs: tuple[MachineMotion, ...]
    payload_mass: Array | None = None
    battery_energy_J: dict[str, float] | None = None
    battery_period: str = "cycle"
    ground: float | None = None  # the soil's ground level in the description's world y [m]; None: none given
    battery_power: dict[str, Array] | None = None  # each design's battery power over the cycle (K,) [W]


def is_machine_result(result_dir: str | Path) -> bool:
    """True when the folder's ``result.json`` stores machine designs (``{"names", "values"}``, :class:`MachineDesign`).

    Only that one key is looked at: a missing or unreadable file gives False, and the crane's loader
    (:func:`hiab_sim.render.playback.load_playback`) then names what is wrong on one line.
    """
    path = Path(result_dir) / RESULT_FILE
    if not path.is_file():
        return False
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, ValueError):
        return False  # reported by the crane's loader, which reads the same file
    optimal = document.get("optimal") if isinstance(document, dict) else None
    lengths = optimal.get("lengths") if isinstance(optimal, dict) else None
    return isinstance(lengths, dict) and "names" in lengths


def load_machine_playback(result_dir: str | Path) -> MachinePlayback:
    """Read a machine file's result folder (see the module docstring).

    Raises:
        ConfigError: a missing or corrupt file, or arrays whose shapes do not fit the machine.
        InvalidInputError: the result is a crane file's.

    """
    result = read_result(result_dir)
    machine = result_machine(result_dir, result)
    trajectory = read_trajectory(result_dir)
    time = trajectory.time()
    reference = trajectory.get("reference_tcp")
    if reference.ndim != 2 or reference.shape[1] != 3:
        raise ConfigError(f"{trajectory.path}: array 'reference_tcp' has shape {reference.shape}, expected (K, 3)")
    motions = []
    for name in DESIGNS:
        position = trajectory.design(name, "position")
        if position.shape[1] != len(machine.joint_names):
            raise ConfigError(
                f"{trajectory.path}: array '{name}_position' has {position.shape[1]} columns, "
                f"the machine has joints {machine.joint_names}"
            )
        key = f"{name}_electrical_power"
        power = trajectory.design(name, "electrical_power").sum(axis=1) if key in trajectory.arrays else None
        stored = (result.optimal if name == "optimal" else result.initial).lengths
        if not isinstance(stored, MachineDesign):
            raise ConfigError(f"{result_dir}: the {name} design is not a machine design")
        motions.append(MachineMotion(name, result_design(machine, stored, f"result.{name}"), position, power))
    payload = trajectory.get("payload_mass") if "payload_mass" in trajectory.arrays else None
    battery, period = None, "cycle"
    if result.energy is not None:
        battery = {"initial": result.energy.initial.battery_energy_J, "optimal": result.energy.optimal.battery_energy_J}
        period = result.energy.period
    return MachinePlayback(
        machine, time, reference, tuple(motions), payload, battery, period, study_ground(result.study),
        battery_powers(trajectory),
    )  # fmt: skip


def study_ground(study: str) -> float | None:
    """The ground level [m] of the first task with soil in the study file ``study``; None without one or the file."""
    if not Path(study).is_file():
        return None
    from hiab_sim.study.spec.study_file import load_study

    return next((task.soil.ground for task in load_study(study).tasks if task.soil is not None), None)


def machine_model_and_qpos(designed: Machine, position: Array) -> tuple[mujoco.MjModel, Array]:
    """The MJCF model of a machine set to its design and loop-consistent qpos (N, nq) for joint positions (N, n).

    A result's design is set by the caller with ``with_design(..., check_bounds=False)``: the solver held
    its bounds to its own tolerance (IPOPT: 1e-8 relative past one).
    """
    model = mujoco.MjModel.from_xml_string(machine_mjcf(designed))
    dynamics = MujocoMachineDynamics(designed)
    ranges = [designed.joint_link(name).joint_range or (0.0, 0.0) for name in designed.joint_names]
    low, high = np.array(ranges).T
    # the samples lie in the ranges; a resampled frame may pass an end by round-off only
    return model, posed_qpos(dynamics, np.clip(position, low, high))


def machine_reference(data: MachinePlayback) -> Array:
    """The reference TCP path (K, 3) in the MuJoCo world [m]."""
    return source_to_world(data.reference_tcp)

"""The plant's parts on a closed-loop Physics, for the crane's MJCF and any machine file's alike.

The crane's builder (:func:`hiab_sim.env.physics.crane_physics`) and a machine's
(:func:`hiab_sim.env.machine_env.machine_environment`) differ in the mechanism they compile (the
crane MJCF of :mod:`hiab_sim.model.mjcf`, a machine tree of :mod:`hiab_sim.machine.dynamics.mjcf_build`)
and in how its bodies carry the mismatch (:mod:`hiab_sim.env.plant.mismatch`); what the plant adds
to the model and to the drives is this module's, named by the actuators and joints the builder
passes (nothing here knows a machine's names):

* :func:`compliant_stiffness`: k_s per drive of an enabled two-mass drive train (the EMLA file's
  ``drive_stiffness`` at the planned mean stroke, :func:`~hiab_sim.env.plant.drivetrain.drive_train_stiffness`),
  checked against the physics step; the builder then moves the rotor off the slide (armature
  ``rod_side_mass_kg``, no damping) and makes the slides' motors the springs (:func:`spring_actuators`);
* :func:`plant_parts`: the drives (the continuous loop, or the discrete one of
  :mod:`hiab_sim.env.plant.current_loop`), the EMLA file's drive losses, the two-mass trains, the
  winding temperature, the friction meter and the plan's hot-winding resistance (not computed
  while the plant's own winding temperature sets R_s), which
  :meth:`hiab_sim.env.physics.CranePhysics.attach_parts` puts on the Physics.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaSet
from hiab_sim.emla.drive_sim import DriveArrays, DriveSimulator
from hiab_sim.env.drive_losses import DriveLossModel
from hiab_sim.env.planned_energy import DutyPlan, hot_resistance
from hiab_sim.env.plant.config import Plant
from hiab_sim.env.plant.current_loop import DiscreteCurrentLoop
from hiab_sim.env.plant.drivetrain import TwoMassDriveTrain, drive_train_stiffness, locked_rod_frequency_Hz
from hiab_sim.env.plant.friction import FrictionMeter
from hiab_sim.env.plant.sensors import CurrentSensorError
from hiab_sim.env.plant.thermal import WindingTemperature
from hiab_sim.env.reference import PlannedMotion


def active_plant(plant: Plant | None) -> Plant | None:
    """The plant when any effect is on, else None (the planner's model, step for step)."""
    return plant if plant is not None and plant.enabled else None


def compliant_stiffness(emlas: EmlaSet, motion: PlannedMotion, plant: Plant | None, timestep: float) -> Array | None:
    """k_s [N/m] per drive of the plant's enabled drive train at the planned strokes, or None (rigid).

    Raises:
        InvalidInputError: an EMLA without ``screw``/``drive_stiffness`` data, or a rod-side mass below
            k_s h^2 / 2 for the physics step h [s] (:meth:`~hiab_sim.env.plant.config.DriveTrain.check_step`).

    """
    active = active_plant(plant)
    if active is None or not active.drive_train.enabled:
        return None
    stiffness = drive_train_stiffness(emlas, motion.stroke)  # the EMLA file's k_s
    active.drive_train.check_step(timestep, float(stiffness.max()))
    return stiffness


def drive_train_resonance(
    emlas: EmlaSet, motion: PlannedMotion, plant: Plant | None
) -> tuple[Array | None, float | None]:
    """(k_s per drive [N/m], the lowest locked-rod frequency sqrt(k_s / m_m) / 2 pi [Hz]) of a compliant plant.

    (None, None) for a rigid one; m_m = J_m k^2 + M_sm per drive (eq. ``torque_torque``).
    """
    if plant is None or not plant.drive_train.enabled:
        return None, None
    stiffness = drive_train_stiffness(emlas, motion.stroke)
    masses = np.array([p.motor.rotor_inertia * p.transmission_ratio**2 + p.screw_moving_mass for p in emlas])
    return stiffness, float(locked_rod_frequency_Hz(stiffness, masses).min())


def spring_actuators(spec: mujoco.MjSpec, actuators: Iterable[str]) -> None:
    """Make the slides' actuators the drive train's springs: f = ctrl - k_c x - c_c v, unlimited.

    The limits of the EMLA are the motor's (its current limit); the spring carries what the motor
    side and the load make of it. (k_c, c_c) are set every step (:mod:`hiab_sim.env.plant.drivetrain`).
    """
    for name in actuators:
        actuator = spec.actuator(name)
        actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_FALSE
        actuator.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        actuator.gainprm[0] = 1.0
        actuator.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        actuator.biasprm[:3] = [0.0, 0.0, 0.0]


@dataclass(frozen=True)
class PlantParts:
    """What :meth:`hiab_sim.env.physics.CranePhysics.attach_parts` puts on a Physics (module docstring)."""

    drives: DriveSimulator
    losses: DriveLossModel
    drive_train: TwoMassDriveTrain | None
    thermal: WindingTemperature | None
    friction: FrictionMeter | None
    resistance_schedule: Array | None


def plant_parts(
    model: mujoco.MjModel,
    plan: DutyPlan,
    motion: PlannedMotion,
    arrays: DriveArrays,
    plant: Plant | None,
    stiffness: Array | None,
    friction: tuple[tuple[str, ...], tuple[str, ...]],
    bandwidth_hz: float,
) -> PlantParts:
    """The drives and the plant's parts for a compiled model (module docstring).

    Args:
        model: The compiled MuJoCo model (its physics step; the friction meter's joints and tendons).
        plan: The plan (its EMLA set and duty: the drive losses and the hot windings' R_s).
        motion: The planned motion at the physics rate.
        arrays: The simulated drives' parameters (the mismatch's friction included).
        plant: The plant; None or every effect off: the planner's model.
        stiffness: k_s per drive of :func:`compliant_stiffness`, or None (rigid drive trains).
        friction: The joints and tendons with friction (:func:`~hiab_sim.env.plant.friction.add_joint_friction`).
        bandwidth_hz: The continuous current loop's bandwidth [Hz].

    """
    active = active_plant(plant)
    timestep = float(model.opt.timestep)
    drives: DriveSimulator
    if active is not None and active.current_loop.enabled:
        count = len(arrays.names)
        drives = DiscreteCurrentLoop(arrays, active.current_loop, CurrentSensorError(None, count, 1.0), timestep)
    else:
        drives = DriveSimulator(arrays, bandwidth_hz=bandwidth_hz)
    train = None
    if active is not None and stiffness is not None:
        train = TwoMassDriveTrain(active.drive_train, stiffness, arrays.reflected_inertia, arrays.viscous)
    thermal = None
    if active is not None and active.thermal.enabled:
        thermal = WindingTemperature(active.thermal, plan.emlas.as_tuple())
    return PlantParts(
        drives=drives,
        losses=DriveLossModel(plan.emlas),
        drive_train=train,
        thermal=thermal,
        friction=FrictionMeter(model, *friction) if friction[0] else None,
        # the plan's hot windings, unless the plant's own winding temperature sets R_s
        resistance_schedule=None if thermal is not None else hot_resistance(plan, motion, arrays.resistance),
    )

"""The crane ``Physics`` of the closed-loop environment: the MJCF simulation model plus the EMLA drives.

:func:`crane_physics` builds the simulation model of :mod:`hiab_sim.model.drives` for a design's link
lengths (armature J_m k^2, damping b_f, stops, EMLA force limits), placed at the plan's start pose
(joint ``ref``, so ``reset`` lands there), with the end mass made heavier by ``payload_error`` (an
extra body with the end mass's centre of mass and scaled inertia) and the study's payload as a point
mass at the TCP, also scaled; a payload whose force the plan took per sample (a duty mix task's
schedule or inertia, F(t) = m(t) (g - a_ref)) is that force applied at the TCP instead, x (1 + payload_error)
(:mod:`hiab_sim.env.tcp_load`). :class:`CranePhysics` steps the drives of
:mod:`hiab_sim.emla.drive_sim` once per physics step, at the speeds of the slides
(omega_m = k v_x), and applies their rod forces as the actuators' ``ctrl`` before ``mj_step``.

The drives carry the EMLA file's drive losses, the planner's own functions (:mod:`hiab_sim.env.drive_losses`):
the screw and gearbox efficiency between the motor and the rod, and on the DC side the inverter's loss,
the holding brake's coil and release factor. ``energy`` is each drive's DC input over the cycle, the
boundary of the optimiser's energy (``terminal`` the motor terminals' int 3/2 v.i dt). The winding
resistance is the planner's too: with the study's hot windings (:mod:`hiab_sim.emla.duty_energy`) the
drives see R_s at the plan's periodic winding temperature, sample by sample (``resistance_schedule``).

A :class:`~hiab_sim.env.plant.config.Plant` adds what the planner leaves out (:mod:`hiab_sim.env.plant`):
the crane and friction of the mismatch, the hinge and pin friction, a two-mass drive train per EMLA
(the rotor's reflected inertia and the screw friction then move from the slide to the motor side,
which the drive turns and the spring, of the EMLA file's stiffness, joins to the rod), the discrete
current loop with its inverter losses, the sensors the controller reads, and the winding temperature
that sets R_s. With every effect off (or no plant) the model is the one above, step for step.
"""

from __future__ import annotations

import concurrent.futures.thread  # noqa: F401  (registers its exit hook first; see _free_live_physics)
import threading
import weakref
from dataclasses import replace
from typing import Protocol

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.crane.names import LOAD_BODY, TOOL_LINK
from hiab_sim.emla.drive_sim import DriveArrays, DriveSimulator, DriveStep
from hiab_sim.env.drive_losses import DriveLossModel
from hiab_sim.env.plan import DesignPlan
from hiab_sim.env.plant.assembly import PlantParts, active_plant, compliant_stiffness, plant_parts, spring_actuators
from hiab_sim.env.plant.config import Plant
from hiab_sim.env.plant.current_loop import DiscreteCurrentLoop
from hiab_sim.env.plant.drivetrain import TwoMassDriveTrain, coupled_step
from hiab_sim.env.plant.friction import FrictionMeter, add_joint_friction
from hiab_sim.env.plant.mismatch import true_crane, true_drives
from hiab_sim.env.plant.sensors import CurrentSensorError, MotionSensor
from hiab_sim.env.plant.thermal import WindingTemperature
from hiab_sim.env.reference import PlannedMotion
from hiab_sim.env.tcp_load import TcpLoad
from hiab_sim.errors import InvalidInputError
from hiab_sim.model.drives import HomePose, SlideDrives
from hiab_sim.model.mjcf import ACTUATORS, JOINTS, SLIDES, build_spec, source_to_world

#: Every live CranePhysics, freed before the interpreter stops dm-control's render thread.
_LIVE: weakref.WeakSet[CranePhysics] = weakref.WeakSet()


def _free_live_physics() -> None:
    """Free the rendering contexts of every live Physics while dm-control's render executor still runs.

    dm-control frees an OSMesa context from ``__del__`` through a thread pool; at interpreter exit
    that pool is already shut down and Python prints "Exception ignored ... cannot schedule new
    futures after shutdown". Hooks registered with ``threading._register_atexit`` run last-in
    first-out before that shutdown, and this one is registered after the thread pool's own
    hook (imported above), so it runs first.
    """
    for physics in list(_LIVE):
        physics.free()


threading._register_atexit(_free_live_physics)  # type: ignore[attr-defined]


class ExternalLoad(Protocol):
    """A force set before every ``mj_step``: a plan's TCP force (:mod:`hiab_sim.env.tcp_load`)."""

    def apply(self, model: mujoco.MjModel, data: mujoco.MjData, holding: bool) -> None:
        """Set ``data.xfrc_applied``; ``holding``: during a settled start's hold (the first sample's load)."""


class CranePhysics(dm_mujoco.Physics):
    """dm-control Physics whose ``step`` runs the EMLA drives at the physics rate (module docstring)."""

    #: External load applied before each ``mj_step`` (a crane's only with a per-sample payload force) and whether
    #: the cycle's start is held.
    tcp_load: ExternalLoad | None = None
    holding: bool = False

    drives: DriveSimulator
    slide_dofs: NDArray[np.int64]
    tcp_site: int
    current_reference: Array
    last: DriveStep | None
    energy: Array
    copper: Array
    plant: Plant | None
    drive_train: TwoMassDriveTrain | None
    sensor: MotionSensor
    current_error: CurrentSensorError
    thermal: WindingTemperature | None
    friction: FrictionMeter | None
    losses: DriveLossModel
    resistance_schedule: Array | None

    def attach_drives(
        self,
        drives: DriveSimulator,
        losses: DriveLossModel,
        plant: Plant | None = None,
        drive_train: TwoMassDriveTrain | None = None,
        thermal: WindingTemperature | None = None,
        friction: FrictionMeter | None = None,
        joints: tuple[str, ...] = SLIDES,
        actuators: tuple[str, ...] = ACTUATORS,
        resistance_schedule: Array | None = None,
    ) -> None:
        """Attach the drives, their losses and the plant's parts; clear the energy counters.

        ``joints`` are the actuated slides and ``actuators`` their motors, in the drives' order (the
        crane's lift, tilt, telescope by default; a machine's chains, :mod:`hiab_sim.env.machine_env`).
        ``resistance_schedule`` (N, n) [ohm]: R_s per physics step of the cycle (the plan's hot windings;
        None: the drives' own R_s), unused while the plant's winding temperature runs.
        """
        _LIVE.add(self)
        self.drives = drives
        self.losses = losses
        self.resistance_schedule = resistance_schedule
        self.plant = plant
        self.drive_train = drive_train
        self.thermal = thermal
        self.friction = friction
        self.slide_dofs = np.array([self.model.jnt_dofadr[self.model.name2id(s, "joint")] for s in joints])
        self.tcp_site = int(self.model.name2id("tcp", "site"))
        self.actuator_ids = np.array([self.model.name2id(name, "actuator") for name in actuators])
        self.current_reference = np.zeros(len(joints))
        h = float(self.model.opt.timestep)
        sensors = plant.sensors if plant is not None else None
        self.sensor = MotionSensor(sensors, drives.drives.ratio, h)
        rate = plant.current_loop.rate_Hz if plant is not None else 1.0 / h
        self.current_error = CurrentSensorError(sensors, len(joints), rate * h)
        if isinstance(drives, DiscreteCurrentLoop):
            drives.sensor = self.current_error
        self.reset_counters()

    def attach_parts(
        self, parts: PlantParts, plant: Plant | None, joints: tuple[str, ...], actuators: tuple[str, ...]
    ) -> None:
        """:meth:`attach_drives` with the parts of :func:`hiab_sim.env.plant.assembly.plant_parts`."""
        self.attach_drives(
            parts.drives,
            parts.losses,
            plant,
            drive_train=parts.drive_train,
            thermal=parts.thermal,
            friction=parts.friction,
            joints=joints,
            actuators=actuators,
            resistance_schedule=parts.resistance_schedule,
        )

    def motor_state(self) -> tuple[Array, Array]:
        """Motor-side stroke [m] and rate [m/s] at the rod (the rod's own when the drive train is rigid)."""
        if self.drive_train is None:
            return self.stroke().copy(), self.rod_velocity().copy()
        return self.drive_train.position.copy(), self.drive_train.velocity.copy()

    def reset_counters(self) -> None:
        """Zero the accumulated electrical and copper energy and the limit counters."""
        self.last = None
        n = len(self.slide_dofs)
        self.energy = np.zeros(n)
        self.terminal = np.zeros(n)
        self.copper = np.zeros(n)
        self.transmission_loss = np.zeros(n)
        self.brake_coil = np.zeros(n)
        self.brake_carried = np.zeros(n)
        self.steps = 0
        self.current_limited_steps = np.zeros(n)
        self.voltage_limited_steps = np.zeros(n)
        self.inverter = np.zeros(n)
        self.drive_train_loss = np.zeros(n)
        self.friction_loss = 0.0

    def rod_velocity(self) -> Array:
        """v_x of the actuated slides (the crane's x1, x2, xt2) [m/s]."""
        return np.asarray(self.data.qvel[self.slide_dofs])

    def stroke(self) -> Array:
        """Strokes x of the actuated slides (the crane's x1, x2, xt2) [m]."""
        return np.asarray(self.data.qpos[self.slide_dofs])

    def step(self, nstep: int = 1) -> None:
        """Advance nstep physics steps, each: drives over the step, then ``mj_step`` with their rod forces."""
        if self.plant is not None and self.plant.enabled:
            self._plant_step(nstep)
            return
        model, data = self.model.ptr, self.data.ptr
        h = float(model.opt.timestep)
        ratio = self.drives.drives.ratio
        with self.check_invalid_state():
            for _ in range(nstep):
                self._scheduled_resistance(h)
                v = data.qvel[self.slide_dofs].copy()
                omega = ratio * v
                result = self.drives.step(self.current_reference, omega, h)
                self._rigid_step(result.rod_force, omega, h)
                self._book(result, v, h)
                self.sensor.push(data.qpos[self.slide_dofs], data.qvel[self.slide_dofs])
            mujoco.mj_kinematics(model, data)  # site positions of the new state, for observations

    def _rigid_step(self, force: Array, omega: Array, h: float) -> None:
        """One ``mj_step`` with the drives' rod force [N] on rigid drive trains, less the screw's transmission loss.

        ``omega``: the motor speeds [rad/s] the drives stepped at; the loss's energy is booked at the new rates.
        """
        model, data, losses = self.model.ptr, self.data.ptr, self.losses
        tau_tr = None
        if losses.transmission_on:
            force, tau_tr = losses.rigid_rod_force(force, omega, data.qacc[self.slide_dofs])
        data.ctrl[self.actuator_ids] = force
        if self.tcp_load is not None:
            self.tcp_load.apply(model, data, self.holding)
        mujoco.mj_step(model, data)
        if tau_tr is not None:
            self.transmission_loss += tau_tr * self.drives.drives.ratio * data.qvel[self.slide_dofs] * h

    def _scheduled_resistance(self, h: float) -> None:
        """R_s of the plan's hot windings at this step (none while the plant's own winding model runs)."""
        schedule = self.resistance_schedule
        if schedule is None or self.thermal is not None:
            return
        k = 0 if self.holding else int(min(max(round(self.data.time / h), 0), len(schedule) - 1))
        self.drives.drives = replace(self.drives.drives, resistance=schedule[k])

    def _book(self, result: DriveStep, rod_velocity: Array, h: float) -> None:
        """Add one step's energies: the DC input with the EMLA file's losses, terminals, copper, limits."""
        dc, inverter, coil, carried = self.losses.dc_energy(result, rod_velocity, h)
        self.energy += dc
        self.terminal += result.electrical_energy
        self.copper += result.copper_energy
        self.inverter += inverter
        self.brake_coil += coil
        self.brake_carried += carried
        self.current_limited_steps += result.current_limited
        self.voltage_limited_steps += result.voltage_limited
        self.steps += 1
        self.last = result

    def _plant_step(self, nstep: int) -> None:
        """:meth:`step` with the plant's effects (module docstring)."""
        model, data = self.model.ptr, self.data.ptr
        h = float(model.opt.timestep)
        ratio = self.drives.drives.ratio
        train, thermal, friction = self.drive_train, self.thermal, self.friction
        losses = self.losses
        discrete = isinstance(self.drives, DiscreteCurrentLoop)
        with self.check_invalid_state():
            for _ in range(nstep):
                self._scheduled_resistance(h)
                v = data.qvel[self.slide_dofs].copy()
                omega = ratio * (v if train is None else train.velocity)
                reference = self.current_reference if discrete else self.current_reference - self.current_error.sample()
                result = self.drives.step(reference, omega, h)
                if train is None:
                    self._rigid_step(result.rod_force, omega, h)
                else:
                    force = result.rod_force
                    tau_tr = None
                    if losses.transmission_on:  # the screw force at the step's start: spring plus screw friction
                        screw = train.spring_force(data.qpos[self.slide_dofs], v) + train.viscous * train.velocity
                        tau_tr, _ = losses.loss_torque(screw, omega)
                        force = force - ratio * tau_tr
                    if self.tcp_load is not None:
                        self.tcp_load.apply(model, data, self.holding)
                    loss = coupled_step(train, model, data, self.actuator_ids, self.slide_dofs, force, h)
                    self.drive_train_loss += loss
                    if tau_tr is not None:
                        self.transmission_loss += tau_tr * ratio * train.velocity * h
                if friction is not None:
                    self.friction_loss += h * friction.power(model, data)
                if thermal is not None:
                    thermal.advance(result.copper_energy, h)
                    self.drives.drives = replace(self.drives.drives, resistance=thermal.resistance())
                self._book(result, v, h)
                self.sensor.push(*self.motor_state())
            mujoco.mj_kinematics(model, data)  # site positions of the new state, for observations


def crane_physics(
    plan: DesignPlan,
    motion: PlannedMotion,
    timestep: float,
    payload_error: float,
    bandwidth_hz: float,
    plant: Plant | None = None,
) -> CranePhysics:
    """Build the simulation Physics of a design at its plan's start (module docstring)."""
    if not (np.isfinite(payload_error) and 0.0 <= payload_error <= 2.0):
        raise InvalidInputError("payload_error", payload_error, "must lie in [0, 2] (end mass heavier than planned)")
    active = active_plant(plant)
    slides = SlideDrives.from_emla(plan.emlas)
    arrays = DriveArrays.from_params(plan.emlas)
    crane = plan.crane
    if active is not None:
        crane = true_crane(crane, active.mismatch)
        arrays, slides = true_drives(arrays, slides, active.mismatch)
    stiffness = compliant_stiffness(plan.emlas, motion, plant, timestep)
    if active is not None and stiffness is not None:  # the rotor and the screw friction move to the motor side
        rod_side = active.drive_train.rod_side_mass_kg
        slides = replace(slides, armature=(rod_side, rod_side, rod_side), damping=(0.0, 0.0, 0.0))
    spec = build_spec(crane, plan.lengths, slides)
    names = [spec.joints[i].name for i in range(len(spec.joints))]
    home = HomePose(
        qpos={name: float(motion.qpos[0, i]) for i, name in enumerate(names)},
        force=(float(motion.force[0, 0]), float(motion.force[0, 1]), float(motion.force[0, 2])),
    )
    spec = build_spec(crane, plan.lengths, slides, home)
    spec.option.timestep = timestep
    # Implicit in the velocity-dependent forces (the slides' damping); 3x cheaper than the template's RK4.
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    if stiffness is not None:
        spring_actuators(spec, ACTUATORS)
    friction: tuple[tuple[str, ...], tuple[str, ...]] = ((), ())
    if active is not None and active.joint_friction.enabled:
        friction = add_joint_friction(spec, active.joint_friction, hinges=JOINTS)
    _add_payload(spec, plan, payload_error)
    _add_view(spec, motion)
    physics = CranePhysics.from_model(dm_mujoco.wrapper.MjModel(spec.compile()))
    parts = plant_parts(physics.model.ptr, plan, motion, arrays, plant, stiffness, friction, bandwidth_hz)
    physics.attach_parts(parts, plant, SLIDES, ACTUATORS)
    if plan.tcp_force is not None and plan.payload_force is not None:  # the task's F(t), as the plan's ID took it
        at = plan.time[0] + motion.time
        force, payload = (source_to_world(plan.force_at(f, at)) for f in (plan.tcp_force, plan.payload_force))
        physics.tcp_load = TcpLoad(physics.model.ptr, force, timestep, payload, 1.0 + payload_error)
    return physics


def _add_view(spec: mujoco.MjSpec, motion: PlannedMotion) -> None:
    """Visual only: the TCP reference as grey dots and a camera ``closed_loop`` framing crane and path."""
    path = motion.reference_tcp[:: max(1, len(motion.reference_tcp) // 120)]
    for point in path:
        geom = spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.012, 0.0, 0.0], pos=list(point))
        geom.contype, geom.conaffinity, geom.group = 0, 0, 2
        geom.rgba = [0.35, 0.35, 0.35, 1.0]
    centre = 0.5 * (path.min(axis=0) + np.zeros(3))  # between the crane's base and the work area
    centre[2] = 0.5 * (path[:, 2].max() + 0.0) + 0.2
    spec.worldbody.add_camera(
        name="closed_loop", pos=[centre[0] + 0.2, -7.0, centre[2]], xyaxes=[1, 0, 0, 0, 0, 1], fovy=40.0
    )


def _add_payload(spec: mujoco.MjSpec, plan: DesignPlan, payload_error: float) -> None:
    """Extra end mass (payload_error x end mass) and the study's payload x (1 + payload_error) at the TCP.

    The payload is a point mass at the TCP unless the plan carries its force per sample
    (:attr:`~hiab_sim.env.plan.DesignPlan.tcp_force`: a schedule or its inertia), which
    :func:`crane_physics` applies as the plan's force instead.
    """
    rod = spec.body(TOOL_LINK)
    if payload_error != 0.0:
        end = next(body for body in plan.crane.bodies if body.name == LOAD_BODY)
        extra = rod.add_body(name="end_mass_error", pos=list(end.com))
        inertia = np.asarray(end.inertia) * payload_error
        extra.explicitinertial = True
        extra.mass = end.mass * payload_error
        extra.ipos = [0.0, 0.0, 0.0]
        extra.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]
    if plan.payload > 0.0 and plan.tcp_force is None:  # a plan's F(t) is applied as a force (crane_physics)
        tcp = plan.crane.tcp_in_telescope_rod
        body = rod.add_body(name="payload", pos=list(tcp.position))
        body.explicitinertial = True
        body.mass = plan.payload * (1.0 + payload_error)
        body.inertia = [1e-6, 1e-6, 1e-6]


__all__ = ["JOINTS", "CranePhysics", "crane_physics"]

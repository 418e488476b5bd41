"""The plant description: what the simulated crane has that the planner leaves out, effect by effect.

Each effect is a frozen dataclass with an ``enabled`` switch and its data in SI units; a
:class:`Plant` holds one of each, the (field, source) provenance of every number, and derives the
variants the report needs (:meth:`Plant.ideal`, :meth:`Plant.only`). Every range is checked when an
object is built, with an :class:`~hiab_sim.errors.InvalidInputError` naming field, value and range.
The equations that use the data are in the modules of this package; ``docs/plant.md`` lists them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import Any

from hiab_sim.checks import check_range
from hiab_sim.errors import InvalidInputError

Vector3 = tuple[float, float, float]


def _check(section: Any, where: str, ranges: dict[str, tuple[float | None, float | None, str]]) -> None:
    """Check each named field against (low, high, unit); ``enabled`` must be a bool."""
    enabled = section.enabled
    if not isinstance(enabled, bool):
        raise InvalidInputError(f"{where}.enabled", enabled, "must be true or false")
    for name, (low, high, unit) in ranges.items():
        check_range(f"{where}.{name}", getattr(section, name), low, high, unit)


@dataclass(frozen=True)
class DriveTrain:
    """Two-mass drive train per EMLA: the motor side (rotor reflected to the rod) on a spring to the rod.

    The spring's stiffness k_s is not plant data: it is the EMLA file's ``drive_stiffness``
    (:func:`hiab_sim.env.plant.drivetrain.drive_train_stiffness`), the one owner of the number.

    Attributes:
        enabled: Model the compliance (off: the rotor inertia is rigid with the rod, as the planner has it).
        damping_ratio: zeta of the locked-rod mode, c_s = 2 zeta sqrt(k_s m_m) [-], in [0, 1].
        backlash_m: Total free play 2 b between the motor side and the rod [m], >= 0.
        rod_side_mass_kg: Mass moving with the rod on the load side of the spring (nut, push tube, rod
            eye) [kg] >= 0, added to the slide; at least k_s h^2 / 2 for the physics step h
            (:mod:`hiab_sim.env.plant.drivetrain`).

    """

    enabled: bool
    damping_ratio: float
    backlash_m: float
    rod_side_mass_kg: float

    def __post_init__(self) -> None:
        _check(
            self,
            "drive_train",
            {
                "damping_ratio": (0.0, 1.0, ""),
                "backlash_m": (0.0, 0.01, "m"),
                "rod_side_mass_kg": (0.0, 1e4, "kg"),
            },
        )

    def check_step(self, h: float, stiffness: float) -> None:
        """Raise unless the rod-side mass keeps the local modes of a spring k_s [N/m] stable at the step h [s]."""
        if self.enabled:
            low = 0.5 * stiffness * h * h
            check_range("drive_train.rod_side_mass_kg", self.rod_side_mass_kg, low, None, "kg (k_s h^2 / 2)")


@dataclass(frozen=True)
class JointFriction:
    """Coulomb and viscous friction in the boom hinges and in the actuators' two pins.

    Attributes:
        enabled: Model the friction.
        hinge_coulomb_N_m: Coulomb torque of a boom hinge [N m] >= 0.
        hinge_viscous_N_m_s_per_rad: Viscous coefficient of a boom hinge [N m s/rad] >= 0.
        pin_coulomb_N_m: Coulomb torque of an actuator pin (base pivot, rod end) [N m] >= 0.
        pin_viscous_N_m_s_per_rad: Viscous coefficient of an actuator pin [N m s/rad] >= 0.

    """

    enabled: bool
    hinge_coulomb_N_m: float
    hinge_viscous_N_m_s_per_rad: float
    pin_coulomb_N_m: float
    pin_viscous_N_m_s_per_rad: float

    def __post_init__(self) -> None:
        _check(
            self,
            "joint_friction",
            {
                "hinge_coulomb_N_m": (0.0, None, "N m"),
                "hinge_viscous_N_m_s_per_rad": (0.0, None, "N m s/rad"),
                "pin_coulomb_N_m": (0.0, None, "N m"),
                "pin_viscous_N_m_s_per_rad": (0.0, None, "N m s/rad"),
            },
        )


@dataclass(frozen=True)
class Sensors:
    """What the controller measures: the motor-shaft encoder, the current sensors, and a delay.

    Attributes:
        enabled: Model the sensors (off: the controller sees the exact motor-side stroke and rate).
        encoder_counts_per_rev: Encoder resolution on the motor shaft [counts/rev], an integer >= 4.
        current_noise_rms_A: White noise of each current sensor per sample at the inverter rate [A] >= 0.
        current_offset_A: Offset of the q-axis current measurement [A].
        delay_s: Delay of the stroke and rate measurements [s] in [0, 0.05] (rounded to physics steps).
        seed: Seed of the noise generator (runs are reproducible).

    """

    enabled: bool
    encoder_counts_per_rev: int
    current_noise_rms_A: float
    current_offset_A: float
    delay_s: float
    seed: int = 0

    def __post_init__(self) -> None:
        _check(
            self,
            "sensors",
            {
                "current_noise_rms_A": (0.0, None, "A"),
                "current_offset_A": (-100.0, 100.0, "A"),
                "delay_s": (0, 0.05, "s"),
            },
        )
        check_range("sensors.encoder_counts_per_rev", self.encoder_counts_per_rev, 4, None, integral=True)
        check_range("sensors.seed", self.seed, 0, None, integral=True)


@dataclass(frozen=True)
class CurrentLoop:
    """The current loop in discrete time at the inverter's rate, with the inverter's dead time.

    The inverter's conduction, switching and standby losses are not plant data: they are the EMLA
    file's ``drive_losses`` (:func:`hiab_sim.emla.losses.inverter_loss`), charged in every closed loop
    (:mod:`hiab_sim.env.drive_losses`), so the planner and the plant count them once, the same way.

    Attributes:
        enabled: Model the discrete loop (off: the continuous loop of :mod:`hiab_sim.emla.drive_sim`).
        rate_Hz: Control and PWM rate f_s [Hz] in [1 kHz, 1 MHz]; the voltage is held one period
            and applied one period after the sample (computation delay).
        bandwidth_Hz: Current-loop bandwidth w_c / 2 pi of the PI design [Hz] > 0, < rate_Hz / 4.
        dead_time_s: Dead time t_d of each inverter leg [s] >= 0, < 0.1 / rate_Hz.
        dc_link_voltage_V: V_dc [V] > 0; the dead-time voltage error is (4/pi) t_d f_s V_dc.

    """

    enabled: bool
    rate_Hz: float
    bandwidth_Hz: float
    dead_time_s: float
    dc_link_voltage_V: float

    def __post_init__(self) -> None:
        _check(
            self,
            "current_loop",
            {
                "rate_Hz": (1e3, 1e6, "Hz"),
                "bandwidth_Hz": (1.0, self.rate_Hz / 4.0 if math.isfinite(self.rate_Hz) else None, "Hz"),
                "dead_time_s": (0.0, 0.1 / self.rate_Hz if math.isfinite(self.rate_Hz) else None, "s"),
                "dc_link_voltage_V": (1.0, None, "V"),
            },
        )

    @property
    def dead_time_voltage_V(self) -> float:
        """|v_dq| error of the dead time, (4/pi) t_d f_s V_dc [V] (fundamental of the six-step error)."""
        return 4.0 / math.pi * self.dead_time_s * self.rate_Hz * self.dc_link_voltage_V


@dataclass(frozen=True)
class Thermal:
    """Winding temperature carried through the cycles, with R_s(T) = R_ref (1 + alpha (T - T_ref)).

    The thermal capacity and resistance are the EMLA file's (``thermal``: R_th, tau_th, ambient).

    Attributes:
        enabled: Heat the windings (off: R_s is the EMLA file's value throughout).
        temperature_coefficient_per_K: alpha of copper [1/K] in [0, 0.01].
        reference_temperature_C: T_ref at which the EMLA file's R_s holds [deg C].
        initial_temperature_C: Winding temperature at the start of the first cycle [deg C].
        rest_between_cycles_s: Rest after each cycle (zero current, the brake holds) [s] >= 0.

    """

    enabled: bool
    temperature_coefficient_per_K: float
    reference_temperature_C: float
    initial_temperature_C: float
    rest_between_cycles_s: float

    def __post_init__(self) -> None:
        _check(
            self,
            "thermal",
            {
                "temperature_coefficient_per_K": (0.0, 0.01, "1/K"),
                "reference_temperature_C": (-50.0, 200.0, "deg C"),
                "initial_temperature_C": (-50.0, 200.0, "deg C"),
                "rest_between_cycles_s": (0.0, 1e5, "s"),
            },
        )

    def resistance_factor(self, temperature_C: float) -> float:
        """R_s(T) / R_ref = 1 + alpha (T - T_ref) [-]."""
        return 1.0 + self.temperature_coefficient_per_K * (temperature_C - self.reference_temperature_C)


@dataclass(frozen=True)
class Mismatch:
    """The simulated crane differs from the planned one.

    Attributes:
        enabled: Apply the errors.
        end_mass_error: Relative error of the end mass (the load) [-] in [-0.5, 2].
        end_mass_com_offset_m: Shift of the end mass's centre of mass in its link frame [m], each |.| <= 1.
        link_mass_error: Relative error of every other body's mass and inertia [-] in [-0.5, 0.5].
        link_com_shift_m: Shift of every other body's centre of mass along its link's x axis [m], |.| <= 0.5.
        friction_error: Relative error of the EMLAs' screw viscous and rotor Coulomb friction [-] in [-0.9, 2].

    """

    enabled: bool
    end_mass_error: float
    end_mass_com_offset_m: Vector3
    link_mass_error: float
    link_com_shift_m: float
    friction_error: float

    def __post_init__(self) -> None:
        _check(
            self,
            "mismatch",
            {
                "end_mass_error": (-0.5, 2.0, ""),
                "link_mass_error": (-0.5, 0.5, ""),
                "link_com_shift_m": (-0.5, 0.5, "m"),
                "friction_error": (-0.9, 2.0, ""),
            },
        )
        offset = self.end_mass_com_offset_m
        if not (isinstance(offset, tuple) and len(offset) == 3):
            raise InvalidInputError("mismatch.end_mass_com_offset_m", str(offset), "must be three numbers", "m")
        for i, value in enumerate(offset):
            check_range(f"mismatch.end_mass_com_offset_m[{i}]", value, -1.0, 1.0, "m")


#: The effects, in the order of the report.
EFFECTS: tuple[str, ...] = ("drive_train", "joint_friction", "sensors", "current_loop", "thermal", "mismatch")


@dataclass(frozen=True)
class Plant:
    """The simulated plant: one section per effect (see :data:`EFFECTS`), with provenance.

    Attributes:
        name: What reports call it (the preset name or the file).
        provenance: (dotted field, source) pairs; the source's first word is read, estimate, derived or model.

    """

    name: str
    drive_train: DriveTrain
    joint_friction: JointFriction
    sensors: Sensors
    current_loop: CurrentLoop
    thermal: Thermal
    mismatch: Mismatch
    provenance: tuple[tuple[str, str], ...] = field(default=(), repr=False)

    @property
    def enabled(self) -> tuple[str, ...]:
        """Names of the effects that are on."""
        return tuple(name for name in EFFECTS if getattr(self, name).enabled)

    def with_effects(self, names: tuple[str, ...], label: str | None = None) -> Plant:
        """The plant's data with exactly the effects ``names`` on."""
        unknown = sorted(set(names) - set(EFFECTS))
        if unknown:
            raise InvalidInputError("effects", ", ".join(unknown), f"must be among {', '.join(EFFECTS)}")
        sections = {name: replace(getattr(self, name), enabled=name in names) for name in EFFECTS}
        return replace(self, name=label or self.name, **sections)

    def ideal(self) -> Plant:
        """Every effect off: the planner's own model (today's closed loop)."""
        return self.with_effects((), "ideal")

    def only(self, name: str) -> Plant:
        """Only the effect ``name`` on."""
        return self.with_effects((name,), name)

    def source_of(self, key: str) -> str:
        """Provenance of a dotted field such as ``drive_train.damping_ratio``."""
        return dict(self.provenance).get(key, "unspecified")


def section_fields(cls: type) -> tuple[str, ...]:
    """The YAML keys of a section dataclass."""
    return tuple(f.name for f in fields(cls))

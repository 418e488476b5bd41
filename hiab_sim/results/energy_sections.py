"""Typed energy sections of ``result.json``: battery energy and both objectives, thermal, hydraulics, co-design.

Three optional top-level sections of :class:`hiab_sim.results.schema.Result` (absent from older files):

* ``energy`` (:class:`EnergyReport`): for the initial and the optimal design on the fine grid, the
  battery energy (exact: the number that is the battery's), the smooth one the solver saw and its
  bound, the paper's cost ``costf2`` [W^2 s] (a squared power, not an energy), per-actuator drawn
  int max(P_i, 0) dt and net energies, and the thermal state of each motor over the study's duty.
* ``hydraulic_baseline`` (:class:`HydraulicBaseline`): the crane's valve-controlled cylinders for
  the same motion and loads, constant-pressure and load-sensing supply, initial and optimal.
* ``codesign`` (:class:`Codesign`): the mounting optimum of every transmission combination.

Energies [J], temperatures [deg C], torques [N m], pressures [Pa].
"""

from __future__ import annotations

from dataclasses import dataclass

from hiab_sim.results.codec import optional
from hiab_sim.results.design_values import DesignValues


def battery_period(duty: object | None) -> str:
    """What a battery energy covers: ``"duty period"`` (cycle and rest) under a duty model, else ``"cycle"``."""
    return "duty period" if duty is not None else "cycle"


@dataclass(frozen=True)
class ActuatorThermal:
    """One motor over the duty period (:func:`hiab_sim.emla.thermal_check`, exact switching)."""

    rms_torque_Nm: float
    continuous_torque_Nm: float
    peak_winding_temperature_C: float
    max_winding_temperature_C: float
    torque_margin: float  # 1 - tau_rms / tau_cont, >= 0 within the limit
    temperature_margin_K: float  # T_max - T_peak


@dataclass(frozen=True)
class MotorDuty:
    """One motor over the duty period with the study's duty model (:mod:`hiab_sim.emla.duty_energy`)."""

    hold: str  # brake | motor | none (the rest free: zero torque, zero power)
    rest_energy_J: float  # at the drive over the rest: holding copper, inverter, coil, brake transitions
    rest_copper_energy_J: float
    rest_torque_Nm: float  # motor torque through the rest (0 with the brake)
    first_pose_torque_Nm: float  # static motor torque that holds the cycle's first pose
    last_pose_torque_Nm: float  # ... and its last (the rest pose)
    runaway: bool  # no fixed point of the winding temperature below the insulation limit
    brake_holding_torque_Nm: float | None = optional()  # M4 of the holding brake
    brake_margin: float | None = optional()  # 1 - max |pose torque| / M4, >= 0 where the brake holds
    mean_winding_temperature_C: float | None = optional()  # over the cycle's samples
    peak_winding_temperature_C: float | None = optional()
    peak_resistance_factor: float | None = optional()  # R_s(T_peak) / R_s,ref
    rest_standby_energy_J: float | None = optional()  # the part of rest_energy_J that is the inverter's standby


@dataclass(frozen=True)
class DutyEnergy:
    """One design's energy over a duty period at the battery: hot and cold windings, with and without the hold.

    ``battery_energy_by_model_J`` has the battery energy of the cycle plus the rest for
    ``cold_windings_free_rest`` (R_s at its reference temperature, the rest at zero torque and zero
    power: the per-sample model), ``hot_windings_free_rest``, ``cold_windings_with_hold`` and
    ``hot_windings_with_hold`` (the study's model, = ``battery_energy_J``).
    """

    hold: str
    battery_energy_J: float  # the battery's: hot windings, the hold, exact, cycle + rest
    cycle_battery_energy_J: float
    rest_battery_energy_J: float
    hot_winding_extra_J: float  # what R_s(T) adds: hot - cold, both with the hold
    hold_extra_J: float  # what the hold adds: with - without, both hot
    dc_bus_drawn_energy_J: float  # int max(bus power, 0) dt over the cycle: credit passed between drives
    no_regeneration_energy_at_battery_J: float  # the cycle with no regeneration at all, at the battery
    battery_energy_by_model_J: dict[str, float]
    motors: dict[str, MotorDuty]
    infeasible: tuple[str, ...]  # one line per motor whose winding runs away or whose brake cannot hold


@dataclass(frozen=True)
class DesignEnergy:
    """One design on the fine grid: battery energy, the paper's cost, per-actuator energies, thermal state.

    ``battery_energy_J`` is exact at the battery, with the duty model's hot windings and rest where the
    study has one (``duty``). ``drawn_energy_J`` and ``net_energy_J`` are each drive's exact power over
    the cycle at the reference (cold) winding resistance, at the drive's input: without the hot
    windings' extra copper loss (``duty.hot_winding_extra_J``) and the rest.
    """

    battery_energy_J: float
    battery_energy_smooth_J: float  # the solver's: smooth battery kinks on the solver's (smooth) drive powers
    smoothing_bound_J: float  # bound of the battery and inverter kinks' smoothing alone (BatteryParams)
    costf2_W2s: float
    drawn_energy_J: dict[str, float]
    net_energy_J: dict[str, float]
    thermal: dict[str, ActuatorThermal] | None = optional()
    drive_loss_energy_J: dict[str, dict[str, float]] | None = optional()  # only with drive_losses enabled
    # with drive_losses enabled: the part of smooth - exact that the smoothed drive losses (brake, direction-
    # dependent efficiency, inverter current) add, beyond the battery kinks' smoothing_bound_J
    drive_loss_smoothing_J: float | None = optional()
    duty: DutyEnergy | None = optional()  # with the study's duty model (hot windings, the hold)


@dataclass(frozen=True)
class EnergyReport:
    """Both objectives and the battery's energy for the initial and optimal designs."""

    objective: str
    note: str
    battery: dict[str, float]
    drive_losses: dict[str, str]
    duty: str
    initial: DesignEnergy
    optimal: DesignEnergy
    battery_energy_saved_J: float
    battery_energy_saved_percent: float
    # a duty mix whose weights are cycles per hour: each motor's RMS torque over the hour at the optimum
    # (sqrt(sum_k w_k int_k tau^2 dt / 3600 s), order-independent) and the hour's seconds of work
    hourly_rms_torque_Nm: dict[str, float] | None = optional()
    hourly_work_s: float | None = optional()

    @property
    def period(self) -> str:
        """What ``battery_energy_J`` covers (:func:`battery_period`)."""
        return battery_period(self.optimal.duty)


@dataclass(frozen=True)
class HydraulicVariant:
    """One supply variant over the cycle (:class:`hiab_sim.hydraulics.SupplyResult`)."""

    input_energy_J: float
    input_energy_per_actuator_J: dict[str, float]
    system_efficiency: float
    delivered_work_J: dict[str, float]
    meter_in_loss_J: dict[str, float]
    meter_out_loss_J: dict[str, float]
    friction_loss_J: dict[str, float]
    pump_motor_loss_J: float
    max_load_pressure_Pa: float
    pressure_shortfall_samples: int


@dataclass(frozen=True)
class HydraulicAtBattery:
    """One hydraulic variant over the cycle at the battery (:mod:`hiab_sim.hydraulics.battery_boundary`)."""

    cycle_battery_energy_J: float  # energy taken from the battery over the cycle
    terms_J: dict[str, float]  # useful work and every loss, summing to cycle_battery_energy_J
    max_pilot_pressure_Pa: float  # largest counterbalance pilot pressure the pump supplied
    pressure_shortfall_samples: int
    emla_saving_percent: float  # 1 - EMLA cycle battery energy / this, both at the battery, same cycle


@dataclass(frozen=True)
class HydraulicDesign:
    """Both supply variants for one design, against the EMLAs' battery energy for the same motion.

    ``constant_pressure`` and ``load_sensing`` (and the savings beside them) are drawn at the pump
    motor's electric input, the EMLA figure at the battery; ``at_battery`` has every variant at the
    battery over the cycle (with counterbalance valves, leakage and the pump's motor and inverter),
    compared with the EMLAs' battery energy of the same cycle (``emla_cycle_battery_energy_J``).
    """

    constant_pressure: HydraulicVariant
    load_sensing: HydraulicVariant
    emla_battery_energy_J: float
    emla_saving_vs_load_sensing_percent: float
    emla_saving_vs_constant_pressure_percent: float
    at_battery: dict[str, HydraulicAtBattery] | None = optional()
    emla_cycle_battery_energy_J: float | None = optional()


@dataclass(frozen=True)
class HydraulicBaseline:
    """The cylinders the EMLAs replace, driven through the same motion and loads (fine grid)."""

    note: str
    supply_pressure_Pa: float
    initial: HydraulicDesign
    optimal: HydraulicDesign


@dataclass(frozen=True)
class TransmissionChoice:
    """Gear ratio G [-] and screw lead rho [m per screw revolution] of one actuator."""

    gear_ratio: float
    screw_lead: float


@dataclass(frozen=True)
class CodesignRow:
    """One transmission combination: its start and its mounting optimum (fine grid, exact battery energy)."""

    transmission: dict[str, TransmissionChoice]
    status: str  # converged | infeasible start | solver failed
    message: str
    initial_battery_energy_J: float | None = optional()
    battery_energy_J: float | None = optional()
    costf2_W2s: float | None = optional()
    objective_value: float | None = optional()  # the study's objective on the fine grid [objective_unit]
    objective_unit: str | None = optional()
    lengths: DesignValues | None = optional()
    max_violation: float | None = optional()
    min_thermal_margin: float | None = optional()
    iterations: int | None = optional()
    wall_time_s: float | None = optional()


@dataclass(frozen=True)
class Codesign:
    """Mounting optimised for every combination of the catalogue; the best against mounting alone.

    ``reference`` is the row of the EMLA file's own transmission (mounting alone); savings are
    relative to the initial design with that transmission.
    """

    objective: str
    note: str
    rows: tuple[CodesignRow, ...]
    best: int
    reference: int
    initial_battery_energy_J: float
    mounting_only_battery_energy_J: float
    codesign_battery_energy_J: float
    mounting_only_saving_percent: float
    codesign_saving_percent: float
    extra_saving_J: float

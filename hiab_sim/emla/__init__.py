"""The EMLA (PMSM + gearbox + screw) electromechanical model: power, losses, envelope and maps.

Public API (vectorised over numpy arrays of samples):

* :func:`load_emla_set` -> :class:`EmlaSet` with ``lift``, ``tilt``, ``telescope`` :class:`EmlaParams`;
* :func:`operating_point`, :func:`electrical_power`, :func:`electrical_power_partials`;
* :func:`envelope_margins`, :func:`envelope_margin_partials`, :data:`ENVELOPE_LIMIT_NAMES`;
* :func:`energy_summary`, :func:`peak_force`, :func:`top_speed`;
* battery energy on a shared DC bus: :class:`BatteryParams`, :func:`battery_energy` (:mod:`hiab_sim.emla.battery`);
* thermal limits: :class:`ThermalParams`, :class:`Duty`, :func:`rms_torque`, :func:`periodic_winding_temperature`
  (:mod:`hiab_sim.emla.thermal`) and :func:`thermal_check` along a trajectory;
* optional drive losses: :class:`DriveLosses` (:mod:`hiab_sim.emla.losses`);
* Park transform in :mod:`hiab_sim.emla.park`, dq equations in :mod:`hiab_sim.emla.pmsm`,
  efficiency maps in :mod:`hiab_sim.emla.maps` (imported on demand: it needs matplotlib).
"""

from __future__ import annotations

from hiab_sim.emla.battery import BatteryEnergy, BatteryParams, battery_energy
from hiab_sim.emla.config import (
    ACTUATOR_NAMES,
    EmlaParams,
    EmlaSet,
    PmsmParams,
    emla_set_from_mapping,
    load_emla_set,
)
from hiab_sim.emla.drive import DriveState, drive_state
from hiab_sim.emla.envelope import (
    ENVELOPE_LIMIT_NAMES,
    envelope_margin_partials,
    envelope_margins,
    within_envelope,
)
from hiab_sim.emla.losses import DriveLosses
from hiab_sim.emla.model import (
    OperatingPoint,
    efficiency,
    electrical_power,
    electrical_power_partials,
    energy_summary,
    operating_point,
    peak_force,
    top_speed,
)
from hiab_sim.emla.park import abc_to_dq0, dq0_power, dq0_to_abc, line_voltage_rms, park_matrix
from hiab_sim.emla.thermal import Duty, ThermalParams, periodic_winding_temperature, rms_torque
from hiab_sim.emla.thermal_check import ThermalCheck, thermal_check

__all__ = [
    "ACTUATOR_NAMES",
    "ENVELOPE_LIMIT_NAMES",
    "BatteryEnergy",
    "BatteryParams",
    "DriveLosses",
    "DriveState",
    "Duty",
    "EmlaParams",
    "EmlaSet",
    "OperatingPoint",
    "PmsmParams",
    "ThermalCheck",
    "ThermalParams",
    "abc_to_dq0",
    "battery_energy",
    "dq0_power",
    "dq0_to_abc",
    "drive_state",
    "efficiency",
    "electrical_power",
    "electrical_power_partials",
    "emla_set_from_mapping",
    "energy_summary",
    "envelope_margin_partials",
    "envelope_margins",
    "line_voltage_rms",
    "load_emla_set",
    "operating_point",
    "park_matrix",
    "peak_force",
    "periodic_winding_temperature",
    "rms_torque",
    "thermal_check",
    "top_speed",
    "within_envelope",
]

"""The motor winding the EMLA thermal tests share: 14 N m continuous torque, 40 deg C ambient, 140 deg C limit."""

from __future__ import annotations

from hiab_sim.emla.thermal import ThermalParams


def motor_thermal(thermal_resistance: float, time_constant: float, label: str = "thermal") -> ThermalParams:
    """That motor's winding model with R_th [K/W] to ambient and time constant tau_th [s] as a test needs them."""
    return ThermalParams(
        continuous_torque=14.0,
        thermal_resistance=thermal_resistance,
        time_constant=time_constant,
        ambient_temperature=40.0,
        max_winding_temperature=140.0,
        label=label,
    )

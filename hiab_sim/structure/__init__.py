"""Structural checks of a mounting: screw buckling, pin loads and the drive train's natural frequencies.

The MuJoCo paths (:mod:`~hiab_sim.structure.pin_loads_mujoco`,
:mod:`~hiab_sim.structure.natural_frequency_mujoco`, :mod:`~hiab_sim.structure.free_vibration`) and the
report helpers (:mod:`~hiab_sim.structure.report`) are imported from their modules.
"""

from hiab_sim.structure.buckling import DEFAULT_SAFETY_FACTOR, BucklingSamples, buckling_samples, critical_load
from hiab_sim.structure.natural_frequency import (
    Modes,
    axial_stiffness,
    bandwidth_margin,
    natural_frequencies,
    working_range_poses,
)
from hiab_sim.structure.pin_loads import Pin, PinLoads, analytic_pin_loads, pins
from hiab_sim.structure.settings import StructureSettings
from hiab_sim.structure.summary import DesignStructure, StructureSummary, design_structure

__all__ = [
    "DEFAULT_SAFETY_FACTOR",
    "BucklingSamples",
    "DesignStructure",
    "Modes",
    "Pin",
    "PinLoads",
    "StructureSettings",
    "StructureSummary",
    "analytic_pin_loads",
    "axial_stiffness",
    "bandwidth_margin",
    "buckling_samples",
    "critical_load",
    "design_structure",
    "natural_frequencies",
    "pins",
    "working_range_poses",
]

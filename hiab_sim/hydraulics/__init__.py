"""The hydraulic baseline the EMLAs replace: valve-controlled cylinders on a constant-pressure or load-sensing pump.

Public API: :class:`Cylinder`, :class:`HydraulicSystem`, :func:`cylinder_from_mapping`,
:func:`hydraulic_cylinders_from_mapping`, :class:`HydraulicSupplyParams`, :func:`cylinder_flows`,
:func:`hydraulic_baseline` (returns one :class:`SupplyResult` per variant in :data:`VARIANTS`).
"""

from __future__ import annotations

from hiab_sim.hydraulics.baseline import (
    VARIANTS,
    CylinderFlows,
    HydraulicSupplyParams,
    SupplyResult,
    cylinder_flows,
    hydraulic_baseline,
)
from hiab_sim.hydraulics.cylinders import (
    Cylinder,
    HydraulicSystem,
    cylinder_from_mapping,
    hydraulic_cylinders_from_mapping,
)

__all__ = [
    "VARIANTS",
    "Cylinder",
    "CylinderFlows",
    "HydraulicSupplyParams",
    "HydraulicSystem",
    "SupplyResult",
    "cylinder_flows",
    "cylinder_from_mapping",
    "hydraulic_baseline",
    "hydraulic_cylinders_from_mapping",
]

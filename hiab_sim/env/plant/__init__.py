"""The closed loop's plant: what the simulated crane has that the planner leaves out, effect by effect.

:func:`load_plant` reads a plant file (the shipped ``realistic``, ``ideal`` or a path) into a
:class:`Plant` of six effects (:data:`EFFECTS`): the two-mass drive train with free play, hinge and
pin friction, sensors, the discrete current loop with inverter losses, the winding temperature, and
the model mismatch. ``docs/plant.md`` gives the equations, the data and their sources.
"""

from __future__ import annotations

from hiab_sim.env.plant.config import (
    EFFECTS,
    CurrentLoop,
    DriveTrain,
    JointFriction,
    Mismatch,
    Plant,
    Sensors,
    Thermal,
)
from hiab_sim.env.plant.load import load_plant

__all__ = [
    "EFFECTS",
    "CurrentLoop",
    "DriveTrain",
    "JointFriction",
    "Mismatch",
    "Plant",
    "Sensors",
    "Thermal",
    "load_plant",
]

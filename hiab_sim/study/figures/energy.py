"""Figure of a result's energy section: EMLA vs hydraulic energy per actuator.

Draws :func:`hiab_sim.hydraulics.figure.plot_energy_comparison` for the optimal design: per
actuator the EMLA's drawn energy int max(P_i, 0) dt against the pump input attributed to each
cylinder, and in total the battery energy against both hydraulic supplies.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from hiab_sim.atomic_io import write_atomic
from hiab_sim.crane.description import Crane
from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.hydraulics import hydraulic_baseline
from hiab_sim.hydraulics.figure import plot_energy_comparison
from hiab_sim.results.schema import Result
from hiab_sim.study.nlp.interface import SampleState


def hydraulic_figure(path: Path, crane: Crane, result: Result, optimal: SampleState) -> list[Path]:
    """Write the EMLA-vs-hydraulic bars of the optimal design to ``path``; [] without cylinders or energy section."""
    cylinders, energy = crane.hydraulic_cylinders, result.energy
    if cylinders is None or energy is None:
        return []
    act = optimal.actuators
    cp, ls = hydraulic_baseline(optimal.joints.time, act.force, act.velocity, cylinders)
    drawn = np.array([energy.optimal.drawn_energy_J[name] for name in ACTUATOR_NAMES])
    title = f"{result.name}, optimal design: EMLA vs the crane's hydraulic cylinders, same motion and loads"
    fig = plot_energy_comparison(ACTUATOR_NAMES, drawn, energy.optimal.battery_energy_J, cp, ls, title)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=120)
    write_atomic(path, buffer.getvalue())
    return [path]

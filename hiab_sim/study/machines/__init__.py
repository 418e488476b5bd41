"""The machine as the study sees it: :class:`~hiab_sim.study.machines.protocol.StudyMachine` and its two sources.

A study names a crane file (``crane:``, :mod:`hiab_sim.crane`: the XS 031's closed-form model,
:class:`~hiab_sim.study.machines.crane_model.CraneModel`) or a machine file (``machine:``,
:mod:`hiab_sim.machine`: any planar parallel-serial machine,
:class:`~hiab_sim.study.machines.machine_model.MachineModel`).
"""

from __future__ import annotations

from hiab_sim.study.machines.crane_model import CraneModel
from hiab_sim.study.machines.protocol import StudyMachine

__all__ = ["CraneModel", "StudyMachine"]

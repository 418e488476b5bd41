"""The machine as the study sees it: :class:`~hiab_sim.study.machines.protocol.StudyMachine` and its two sources.

A study names a crane file (``crane:``, :mod:`hiab_sim.crane`: the XS 031's closed-form model) or a
machine file (``machine:``, :mod:`hiab_sim.machine`: any planar parallel-serial machine).
"""

from __future__ import annotations

from typing import Any, cast

from hiab_sim.crane.description import Crane
from hiab_sim.study.machines.crane_model import CraneModel
from hiab_sim.study.machines.protocol import StudyMachine


def as_study_machine(source: Any) -> StudyMachine:
    """A :class:`StudyMachine` as it is, a :class:`~hiab_sim.crane.description.Crane` as its :class:`CraneModel`."""
    if isinstance(source, Crane):
        return cast(StudyMachine, CraneModel(source))
    return cast(StudyMachine, source)


__all__ = ["CraneModel", "StudyMachine", "as_study_machine"]

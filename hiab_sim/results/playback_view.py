"""The renderer's contract with ``result.json``: the crane, both designs' lengths and, if any, their battery energy.

:class:`PlaybackView` reads only these keys of a result (every other key is ignored), so a video
can be made of any result folder, also one a newer writer made or a test fabricated.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from hiab_sim.crane.description import LinkLengths
from hiab_sim.results.codec import from_json, optional
from hiab_sim.results.energy_sections import battery_period


@dataclass(frozen=True)
class DesignLengths:
    """The part of a design the renderer needs: its link lengths."""

    lengths: LinkLengths


@dataclass(frozen=True)
class BatteryFigure:
    """The part of a design's energy section a video shows: the battery energy [J], and the duty model if any."""

    battery_energy_J: float  # :class:`~hiab_sim.results.energy_sections.DesignEnergy`'s, cycle (+ rest with a duty)
    duty: Any = optional()  # present when the study's duty model adds the rest (the figure is per duty period)


@dataclass(frozen=True)
class PlaybackEnergy:
    """Both designs' battery figures of ``result.json``'s ``energy`` section."""

    initial: BatteryFigure
    optimal: BatteryFigure

    @property
    def period(self) -> str:
        """What ``battery_energy_J`` covers (:func:`~hiab_sim.results.energy_sections.battery_period`)."""
        return battery_period(self.optimal.duty)


@dataclass(frozen=True)
class PlaybackView:
    """The renderer's contract with a result: the crane, both designs' lengths and, if any, their battery energy."""

    crane: str
    initial: DesignLengths
    optimal: DesignLengths
    energy: PlaybackEnergy | None = optional()  # absent in a result without a battery model

    @classmethod
    def from_json(cls, data: Any) -> PlaybackView:
        """Build from a parsed result.json (other keys are ignored)."""
        return from_json(cls, data)

"""A study's manufacturing settings: link-length tolerance and the stroke margin of the working range."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from hiab_sim.checks import check_range
from hiab_sim.crane.tolerance import DEFAULT_STROKE_MARGIN, DEFAULT_TOLERANCE
from hiab_sim.yaml_fields import mapping, number


@dataclass(frozen=True)
class BuildSettings:
    """Manufacturing settings of a study.

    Attributes:
        tolerance: Tolerance t of every link length [m] (> 0, <= 10 mm); the result's design is
            rounded to a multiple of it.
        stroke_margin: Stroke kept free at both ends of the working range the robust rows serve
            [m] (>= 0, <= 50 mm); see :func:`hiab_sim.crane.tolerance.buildable_crane`.

    """

    tolerance: float = DEFAULT_TOLERANCE
    stroke_margin: float = DEFAULT_STROKE_MARGIN

    def __post_init__(self) -> None:
        check_range("build.tolerance", self.tolerance, 0.0, 0.01, "m", low_open=True)
        check_range("build.stroke_margin", self.stroke_margin, 0.0, 0.05, "m")

    @classmethod
    def from_mapping(cls, data: Any) -> BuildSettings:
        """From a study's optional ``build: {tolerance, stroke_margin}`` mapping [m]."""
        if data is None:
            return cls()
        node = mapping(data, "build", {"tolerance", "stroke_margin"}, set())
        values = {key: number(node[key], f"build.{key}") for key in ("tolerance", "stroke_margin") if key in node}
        return cls(**values)

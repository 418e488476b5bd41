"""A task's soil contact: the cutting resistance of a named soil on the tool tip (the TCP), along the reference.

Schema (a task's key, machine-file studies whose tracked coordinates include ``tcp_angle``)::

    soil:
      soil: medium_clay        # a shipped soil (hiab_sim/presets/soil_<name>.yaml) or a soil file
      ground: -0.95737         # m, height of the horizontal ground surface in the world frame
      width: 0.40              # m, the bucket's cutting-edge width

The force is :func:`hiab_sim.machine.dynamics.soil_load.soil_force_on_tcp` (the fundamental
earthmoving equation of Reece 1964 / McKyes 1985, :mod:`hiab_sim.machine.dynamics.soil`) evaluated
on the task's reference: the tip's position and velocity and the bucket's attitude ``tcp_angle``
of the reference r(t). Like a payload's inertia force, it is a schedule of the reference, not of the
NLP's variables: the trajectory tracks the reference within the tracking bands (1 mm), so the depth
it leaves out is at most that band (module docstring of :mod:`hiab_sim.study.spec.payload`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.checks import check_positive, check_range
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.soil import SoilProperties
from hiab_sim.machine.dynamics.soil_file import load_soil
from hiab_sim.machine.dynamics.soil_load import soil_force_on_tcp
from hiab_sim.yaml_fields import mapping, number

#: The tracked coordinate that gives the bucket's attitude.
ATTITUDE = "tcp_angle"


@dataclass(frozen=True)
class SoilContact:
    """The soil a task's tool cuts: its data, the ground level [m] and the cutting-edge width [m]."""

    source: str
    ground: float
    width: float
    soil: SoilProperties = field(repr=False)

    def __post_init__(self) -> None:
        check_range("soil.ground", self.ground, unit="m")
        check_positive("soil.width", self.width, "m")

    def force(self, tracked: tuple[str, ...], position: Array, velocity: Array, gravity: float) -> Array:
        """The soil's force on the TCP (K, 3) in the world [N] along tracked samples (K, n) named ``tracked``."""
        if ATTITUDE not in tracked:
            raise InvalidInputError(
                "soil", self.source, f"needs the bucket's attitude tracked (tracked: [{ATTITUDE}]); tracked: {tracked}"
            )
        k = tracked.index(ATTITUDE)
        planar = soil_force_on_tcp(
            position[:, :2],
            velocity[:, :2],
            position[:, k],
            y_ground=self.ground,
            width_m=self.width,
            soil=self.soil,
            gravity=gravity,
        )
        return np.column_stack([planar, np.zeros(len(planar))])

    @classmethod
    def from_mapping(cls, data: Any, where: str = "soil", folder: Path | None = None) -> SoilContact:
        """Read ``{soil, ground, width}``; a soil file's relative path resolves next to the study (``folder``)."""
        d = mapping(data, where, {"soil", "ground", "width"}, {"soil", "ground", "width"})
        source = str(d["soil"])
        if folder is not None and not Path(source).is_absolute() and (folder / source).is_file():
            source = str(folder / source)
        return cls(
            source=source,
            ground=number(d["ground"], f"{where}.ground"),
            width=number(d["width"], f"{where}.width"),
            soil=load_soil(source),
        )

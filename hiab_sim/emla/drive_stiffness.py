"""Axial stiffness of an EMLA's drive train between its two pins: the data and the series formula.

THK General Catalog, Ball Screw, "Studying the Rigidity": the feed screw system's
1/K = 1/K_s + 1/K_N + 1/K_B, with K_s = A E / L for a screw fixed at one end (L bearing -> nut);
here with the pins in series:

    1/k = (l_0 + x) / (E A_r) + 1/k_nut + 1/k_bearing + n_pin / k_pin        [m/N],

the screw a bar of root section A_r = pi d_r^2 / 4 (E and d_r of the actuator's
:class:`~hiab_sim.emla.config.ScrewColumn`) between its fixed bearing and the nut, l_0 at zero
stroke and growing with the stroke x [m]. The EMLA file's ``drive_stiffness`` section is the one
owner of these numbers: the structure's natural frequencies
(:mod:`hiab_sim.structure.natural_frequency`) and the closed loop's two-mass drive train
(:mod:`hiab_sim.env.plant.drivetrain`) both read :func:`axial_stiffness`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.checks import check_fields, check_range
from hiab_sim.errors import InvalidInputError


class _Screw(Protocol):
    """What the stiffness needs of :class:`~hiab_sim.emla.config.ScrewColumn`."""

    @property
    def root_diameter(self) -> float: ...

    @property
    def elastic_modulus(self) -> float: ...


class _Actuator(Protocol):
    """What the stiffness needs of :class:`~hiab_sim.emla.config.EmlaParams` (no import: config imports this)."""

    @property
    def name(self) -> str: ...

    @property
    def screw(self) -> _Screw | None: ...

    @property
    def stiffness(self) -> DriveStiffness | None: ...


@dataclass(frozen=True)
class DriveStiffness:
    """Axial stiffness data of an EMLA's load path between its two pins (module docstring).

    Attributes:
        support_length: Screw length l_0 between the fixed bearing and the nut at zero stroke [m].
        nut_stiffness: Axial stiffness of the loaded nut [N/m].
        bearing_stiffness: Axial stiffness of the screw's fixed support bearing [N/m].
        pin_stiffness: Radial stiffness of one pin with its eye and bearing [N/m].
        pin_count: Pins in the load path [-] (2 for a pin-to-pin actuator).
        label: Prefix used in error messages.

    """

    support_length: float
    nut_stiffness: float
    bearing_stiffness: float
    pin_stiffness: float
    pin_count: float
    label: str = "drive_stiffness"

    def __post_init__(self) -> None:
        check_fields(
            self,
            positive={
                "support_length": "m",
                "nut_stiffness": "N/m",
                "bearing_stiffness": "N/m",
                "pin_stiffness": "N/m",
            },
        )
        check_range(f"{self.label}.pin_count", self.pin_count, 0.0, 8.0)
        if not float(self.pin_count).is_integer():
            raise InvalidInputError(f"{self.label}.pin_count", self.pin_count, "must be a whole number of pins")


def axial_stiffness(params: _Actuator, stroke: ArrayLike) -> NDArray[np.float64]:
    """Axial stiffness k [N/m] of one drive train between its pins at strokes x [m] (module docstring).

    Raises:
        InvalidInputError: the EMLA has no ``screw`` or no ``drive_stiffness`` data.

    """
    if params.screw is None or params.stiffness is None:
        raise InvalidInputError(f"{params.name}", "no screw or drive_stiffness data", "both sections are needed")
    x = np.asarray(stroke, dtype=float)
    s, t = params.screw, params.stiffness
    area = math.pi * s.root_diameter**2 / 4.0
    compliance = (t.support_length + np.maximum(x, 0.0)) / (s.elastic_modulus * area)
    compliance = compliance + 1.0 / t.nut_stiffness + 1.0 / t.bearing_stiffness + t.pin_count / t.pin_stiffness
    k: NDArray[np.float64] = 1.0 / compliance
    return k

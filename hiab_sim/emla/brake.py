"""Catalogue data of a spring-applied holding brake on the motor shaft (used by :mod:`hiab_sim.emla.hold`)."""

from __future__ import annotations

from dataclasses import dataclass

from hiab_sim.checks import check_fields


@dataclass(frozen=True)
class HoldingBrake:
    """A spring-applied holding brake on the motor shaft (catalogue data).

    Attributes:
        holding_torque: M_4 [N m] > 0, the least static torque the engaged brake holds.
        coil_power: P_coil [W] >= 0 drawn while the brake is released.
        release_time: t_2 [s] >= 0, from energising the coil to the brake being open.
        engage_time: t_1 [s] >= 0, from de-energising the coil to the brake holding.
        label: Prefix of error messages (e.g. ``lift.holding_brake``).

    """

    holding_torque: float
    coil_power: float
    release_time: float
    engage_time: float
    label: str = "holding_brake"

    def __post_init__(self) -> None:
        check_fields(
            self,
            positive={"holding_torque": "N m"},
            non_negative={"coil_power": "W", "release_time": "s", "engage_time": "s"},
        )

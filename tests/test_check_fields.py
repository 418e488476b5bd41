"""The field tables of ``check_fields``: checked in field order, each error as its per-field check gives it."""

from __future__ import annotations

import pytest

from hiab_sim.checks import check_fields
from hiab_sim.emla import load_emla_set
from hiab_sim.emla.brake import HoldingBrake
from hiab_sim.emla.params import EmlaParams
from hiab_sim.errors import InvalidInputError


def test_the_first_bad_field_in_declaration_order_is_named_with_its_unit() -> None:
    """A negative coil power and a NaN holding torque: the torque (declared first) is reported, in N m."""
    with pytest.raises(
        InvalidInputError, match=r"^lift\.holding_brake\.holding_torque = nan N m is out of range: must be > 0$"
    ):
        HoldingBrake(float("nan"), -1.0, 0.0, 0.0, label="lift.holding_brake")
    with pytest.raises(InvalidInputError, match=r"^holding_brake\.coil_power = -1 W is out of range: must be >= 0$"):
        HoldingBrake(10.0, -1.0, 0.0, 0.0)


def test_an_explicit_prefix_replaces_the_label() -> None:
    """EmlaParams names its errors by the actuator's name (it has no label)."""
    lift = load_emla_set("paper").lift
    with pytest.raises(InvalidInputError, match=r"^lift\.screw_lead"):
        EmlaParams(lift.name, lift.motor, lift.gear_ratio, -0.01, 0.0, 0.0)


def test_a_table_naming_no_field_is_a_programming_error() -> None:
    """A misspelt field in a table raises TypeError instead of checking nothing."""
    with pytest.raises(TypeError, match="HoldingBrake has no field holding_torqe"):
        check_fields(HoldingBrake(10.0, 0.0, 0.0, 0.0), positive={"holding_torqe": "N m"})

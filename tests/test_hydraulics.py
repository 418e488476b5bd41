"""Hydraulic baseline: flows, pressures and throttling on a hand case, four quadrants, energy balance, bad input."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.hydraulics import (
    Cylinder,
    HydraulicSupplyParams,
    HydraulicSystem,
    cylinder_flows,
    hydraulic_baseline,
    hydraulic_cylinders_from_mapping,
)

XS031 = load_crane().hydraulic_cylinders
assert XS031 is not None
FRICTIONLESS = HydraulicSystem(XS031.cylinders, supply_pressure=19.0e6)
IDEAL = HydraulicSupplyParams(pump_efficiency=1.0, motor_efficiency=1.0)


def _hand_case() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lift pushes 50 kN out at 0.1 m/s, tilt pulls 20 kN in at 0.05 m/s, telescope is pulled out (5 kN, 0.2 m/s)."""
    t = np.array([0.0, 1.0, 2.0])
    f = np.tile([50.0e3, -20.0e3, -5.0e3], (3, 1))
    v = np.tile([0.1, -0.05, 0.2], (3, 1))
    return t, f, v


def test_flows_and_load_pressures_on_a_hand_case() -> None:
    """Meter-in flows and load pressures of three cylinders in three quadrants, computed by hand."""
    _, f, v = _hand_case()
    flows = cylinder_flows(f, v, FRICTIONLESS, IDEAL)
    # lift: piston side, 0.1 m/s x 5.0265e-3 m^2; tilt: rod side 0.05 x 3.4361e-3; telescope: piston side.
    assert flows.inlet_flow[0] == pytest.approx([5.026548e-4, 1.718058e-4, 3.926991e-4], rel=1e-6)
    # 50 kN / 5.0265e-3 m^2 and 20 kN / 3.4361e-3 m^2; the overrunning telescope needs no inlet pressure.
    assert flows.load_pressure[0] == pytest.approx([9.947184e6, 5.820524e6, 0.0], rel=1e-6)
    assert flows.meter_out_loss[0] == pytest.approx([0.0, 0.0, 1000.0], rel=1e-12)


def test_throttling_losses_of_both_supplies_on_a_hand_case() -> None:
    """Constant pressure throttles p_s - p_L at each valve; load sensing throttles from max p_L + margin."""
    t, f, v = _hand_case()
    cp, ls = hydraulic_baseline(t, f, v, FRICTIONLESS, IDEAL)
    assert cp.meter_in_loss == pytest.approx(2.0 * np.array([4550.442, 2264.311, 7461.283]), rel=1e-6)
    assert ls.pump_pressure == pytest.approx(np.full(3, 11.947184e6), rel=1e-6)
    assert ls.meter_in_loss == pytest.approx(2.0 * np.array([1005.310, 1052.596, 4691.648]), rel=1e-6)
    assert ls.input_energy == pytest.approx(2.0 * 12749.554, rel=1e-6)
    assert cp.pressure_shortfall_samples == 0
    # Work delivered: lift 5 kW and tilt 1 kW for 2 s; the overrunning telescope delivers none.
    assert ls.delivered_work == pytest.approx([10.0e3, 2.0e3, 0.0], rel=1e-12)
    assert ls.system_efficiency == pytest.approx(12.0e3 / (2.0 * 12749.554), rel=1e-6)


def test_lowering_a_load_fills_the_rod_side_and_throttles_the_piston_side() -> None:
    """A pushing cylinder that retracts (f > 0, v < 0) is overrunning: rod-side inflow, all |f v| throttled."""
    f = np.array([[30.0e3, -10.0e3, 0.0]])
    v = np.array([[-0.1, 0.1, 0.0]])
    flows = cylinder_flows(f, v, FRICTIONLESS, IDEAL)
    assert flows.inlet_flow[0, 0] == pytest.approx(0.1 * XS031.cylinder("lift").annulus_area, rel=1e-15)
    assert flows.load_pressure[0, :2] == pytest.approx([0.0, 0.0], abs=0.0)
    assert flows.meter_out_loss[0, :2] == pytest.approx([3000.0, 1000.0], rel=1e-15)


def test_cylinders_at_standstill_draw_no_flow_and_do_not_set_the_load_sensing_pressure() -> None:
    """Below the standstill speed a cylinder holds on its valve: no flow, no load-sensing signal."""
    t = np.array([0.0, 1.0])
    f = np.tile([90.0e3, 10.0e3, 0.0], (2, 1))
    v = np.tile([1e-4, 0.05, 0.0], (2, 1))
    _, ls = hydraulic_baseline(t, f, v, FRICTIONLESS, IDEAL)
    assert ls.pump_pressure == pytest.approx(np.full(2, 10.0e3 / XS031.cylinder("tilt").piston_area + 2.0e6), rel=1e-14)
    assert ls.input_energy_per_actuator[0] == 0.0


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), eta=st.tuples(st.floats(0.3, 1.0), st.floats(0.3, 1.0)))
def test_pump_energy_is_useful_work_plus_friction_throttling_and_pump_motor_losses(
    seed: int, eta: tuple[float, float]
) -> None:
    """E_in = sum_i (W_useful + E_friction + E_meter_in + E_meter_out) + E_pump_motor for both supplies.

    Each balance holds to 1e-12 relative, and to a few ulps of the energies it sums or subtracts: the pump
    motor's loss E_in (1 - eta_p eta_m) is a difference of two numbers of E_in's size, so with eta_p eta_m
    one ulp below 1 (a drawn example) it carries half an ulp of E_in, 2.4e-12 J on 4.2e4 J.
    """
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.01, 0.1, 50))
    f = rng.normal(0.0, 3.0e4, (50, 3))
    v = rng.normal(0.0, 0.1, (50, 3))
    params = HydraulicSupplyParams(pump_efficiency=eta[0], motor_efficiency=eta[1])
    for result in hydraulic_baseline(t, f, v, XS031, params):
        parts = result.useful_work + result.friction_loss + result.meter_in_loss + result.meter_out_loss
        ulps = 1e-15 * (np.abs(parts).sum() + abs(result.input_energy))  # [J], a few ulps of the summed energies
        assert result.input_energy == pytest.approx(parts.sum() + result.pump_motor_loss, rel=1e-12, abs=ulps)
        assert result.input_energy_per_actuator.sum() == pytest.approx(result.input_energy, rel=1e-12)
        expected_loss = result.input_energy * (1 - eta[0] * eta[1])
        assert result.pump_motor_loss == pytest.approx(expected_loss, rel=1e-12, abs=ulps)


def test_load_sensing_never_uses_more_than_constant_pressure_below_the_supply_pressure() -> None:
    """With every load pressure + margin <= p_s, the load-sensing pump draws at most the constant-pressure energy."""
    rng = np.random.default_rng(1)
    t = np.linspace(0.0, 5.0, 200)
    f = rng.uniform(-1.0, 1.0, (200, 3)) * [50.0e3, 50.0e3, 15.0e3]
    v = rng.normal(0.0, 0.1, (200, 3))
    cp, ls = hydraulic_baseline(t, f, v, XS031)
    assert ls.max_load_pressure + 2.0e6 <= 19.0e6
    assert ls.input_energy <= cp.input_energy
    assert 0.0 < cp.system_efficiency < ls.system_efficiency < 1.0


def test_crane_file_carries_the_cylinders_it_was_built_with() -> None:
    """The XS 031 preset gives the 80/45 mm lift and tilt and 50/30 mm telescope cylinders at 190 bar."""
    lift, tilt, telescope = XS031.cylinders  # in the crane's actuator order
    assert (lift.name, tilt.name, telescope.name) == ("lift", "tilt", "telescope")
    assert (lift.bore, lift.rod, telescope.bore, telescope.rod) == (0.08, 0.045, 0.05, 0.03)
    assert XS031.supply_pressure == 19.0e6
    # The EMLA preset's hydraulic comparison forces: 95.5 kN push and 65.3 kN pull at 190 bar.
    assert lift.piston_area * XS031.supply_pressure == pytest.approx(95.5e3, rel=1e-3)
    assert lift.annulus_area * XS031.supply_pressure == pytest.approx(65.3e3, rel=1e-3)


@pytest.mark.parametrize(
    ("field", "build"),
    [
        ("hydraulic_cylinders.lift.rod", lambda: Cylinder("lift", 0.08, 0.08, 0.5)),
        ("hydraulic_cylinders.tilt.bore", lambda: Cylinder("tilt", -0.08, 0.045, 0.5)),
        ("hydraulics.pump_efficiency", lambda: HydraulicSupplyParams(pump_efficiency=0.0)),
        ("hydraulics.motor_efficiency", lambda: HydraulicSupplyParams(motor_efficiency=1.5)),
        ("hydraulics.load_sensing_margin", lambda: HydraulicSupplyParams(load_sensing_margin=-1.0)),
        ("hydraulic_cylinders.supply_pressure", lambda: HydraulicSystem(XS031.cylinders, 0.0, 0.0, 0.0, XS031.label)),
        ("hydraulic.supply_pressure", lambda: HydraulicSystem(XS031.cylinders, supply_pressure=0.0)),
        ("hydraulic.cylinders.boom.rod", lambda: Cylinder("boom", 0.08, 0.09, 0.5, label="hydraulic.cylinders.boom")),
        ("hydraulic.cylinders", lambda: HydraulicSystem((*XS031.cylinders, XS031.cylinders[0]), 19.0e6)),
    ],
)
def test_bad_hydraulic_parameters_name_the_field(field: str, build: object) -> None:
    """A rod as wide as the bore, negative bore, efficiencies outside (0, 1], bad pressures are rejected by name."""
    with pytest.raises(InvalidInputError, match=re.escape(field)):
        build()  # type: ignore[operator]


def test_unknown_key_in_the_cylinder_section_is_a_config_error() -> None:
    """A misspelt key in hydraulic_cylinders is reported, not ignored."""
    data = {
        "lift": {"bore": 0.08, "rod": 0.045, "stroke": 0.59},
        "tilt": {"bore": 0.08, "rod": 0.045, "stroke": 0.59},
        "telescope": {"bore": 0.05, "rod": 0.03, "strok": 1.1},
        "supply_pressure": 19.0e6,
    }
    with pytest.raises(ConfigError, match="telescope"):
        hydraulic_cylinders_from_mapping(data, ("lift", "tilt", "telescope"))


def test_comparison_figure_shows_the_energies_it_was_given() -> None:
    """Left chart: battery and both pump inputs; right chart: per actuator drive and pump inputs, in kJ."""
    from hiab_sim.hydraulics.figure import plot_energy_comparison

    t, f, v = _hand_case()
    cp, ls = hydraulic_baseline(t, f, v, FRICTIONLESS, IDEAL)
    fig = plot_energy_comparison(("lift", "tilt", "telescope"), [1.0e3, 2.0e3, 0.5e3], 2.5e3, cp, ls)
    whole = [p.get_height() for p in fig.axes[0].patches]
    assert whole == pytest.approx(np.r_[2.5, ls.input_energy / 1e3, cp.input_energy / 1e3], rel=1e-12)
    each = [p.get_height() for p in fig.axes[1].patches]
    expected = np.r_[[1.0, 2.0, 0.5], ls.input_energy_per_actuator / 1e3, cp.input_energy_per_actuator / 1e3]
    assert each == pytest.approx(expected, rel=1e-12)
    with pytest.raises(InvalidInputError, match="emla_drawn"):
        plot_energy_comparison(("lift", "tilt"), [1.0, 2.0], 1.0, cp, ls)

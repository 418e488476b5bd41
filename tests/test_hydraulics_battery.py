"""Hydraulic baselines at the battery: energy balances, counterbalance pressures by hand, variants ordered."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from hiab_sim.emla.battery import BatteryParams
from hiab_sim.errors import InvalidInputError
from hiab_sim.hydraulics.battery_boundary import BOUNDARY_VARIANTS, CircuitParams, battery_boundary_baselines
from hiab_sim.hydraulics.cylinders import CounterbalanceValve, Cylinder, HydraulicSystem

CBV = CounterbalanceValve("piston", 3.0, 24.7e6, 0.17e6)
CYLINDERS = HydraulicSystem(
    (
        Cylinder("lift", 0.08, 0.045, 0.59, counterbalance=CBV),
        Cylinder("tilt", 0.08, 0.045, 0.59, counterbalance=CBV),
        Cylinder("telescope", 0.05, 0.03, 1.1),
    ),
    supply_pressure=19e6,
    coulomb_friction=4000.0,
    viscous_friction=3000.0,
)
BATTERY = BatteryParams(1.0, 0.975, 0.975)


def _motion(K: int = 401) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 6.25, K)
    s = np.sin(2 * np.pi * t / 6.25)
    force = np.column_stack([40e3 + 10e3 * s, 25e3 - 8e3 * s, -3e3 + 6e3 * s])  # lift, tilt hold on the piston side
    velocity = np.column_stack([0.05 * s, -0.04 * s, 0.1 * np.cos(2 * np.pi * t / 6.25)])
    return t, force, velocity


@pytest.mark.parametrize("index", range(3))
def test_each_variant_balances_battery_energy_with_work_and_every_loss(index: int) -> None:
    """Battery energy = useful work + friction + every valve, leakage, pump, motor, inverter, battery loss (1e-9)."""
    t, f, v = _motion()
    result = battery_boundary_baselines(t, f, v, CYLINDERS, BATTERY)[index]
    assert result.variant == BOUNDARY_VARIANTS[index]
    assert abs(result.balance_residual) <= 1e-9 * result.battery_energy
    assert all(value >= -1e-9 for key, value in result.terms.items() if key != "useful_work")


def test_lowering_through_a_counterbalance_valve_needs_the_hand_pilot_pressure() -> None:
    """40 kN lowered at 50 mm/s: p_rod = (F_m + p_set A_p) / (A_r + 3 A_p); the valve burns the rest."""
    t = np.linspace(0.0, 1.0, 3)
    f = np.tile([40e3, 0.0, 0.0], (3, 1))
    v = np.tile([-0.05, 0.0, 0.0], (3, 1))
    circuit = CircuitParams(leakage_conductance=0.0, bleed_flow=0.0)
    cp, ls, _ = battery_boundary_baselines(t, f, v, CYLINDERS, BATTERY, circuit)
    a_p, a_r = math.pi / 4 * 0.08**2, math.pi / 4 * (0.08**2 - 0.045**2)
    f_m = -(40e3 - 3000.0 * 0.05 - 4000.0)  # friction opposes the retraction: f_h = f - b |v| - F_c
    p_rod = (f_m + 24.7e6 * a_p) / (a_r + 3.0 * a_p)
    assert ls.max_pilot_pressure == pytest.approx(p_rod, rel=1e-12)
    p_cap = 24.7e6 - 3.0 * p_rod
    assert ls.terms["counterbalance_valves"] == pytest.approx(p_cap * a_p * 0.05, rel=1e-12)
    pump = (p_rod + 2.0e6) * a_r * 0.05
    assert ls.battery_energy == pytest.approx(pump / (0.85 * 0.92 * 0.97 * 0.975), rel=1e-12)
    assert cp.battery_energy > ls.battery_energy


def test_pump_controlled_cylinders_recover_what_the_load_returns_through_the_shared_bus() -> None:
    """An EHA lowering 40 kN returns energy; load sensing pays to lower it: EHA < load sensing < constant pressure."""
    t, f, v = _motion()
    cp, ls, eha = battery_boundary_baselines(t, f, v, CYLINDERS, BATTERY)
    assert eha.battery_energy < ls.battery_energy < cp.battery_energy
    assert eha.terms["useful_work"] == pytest.approx(ls.terms["useful_work"], rel=0.05)
    no_leak = battery_boundary_baselines(t, f, v, CYLINDERS, BATTERY, CircuitParams(leakage_conductance=0.0))[1]
    assert no_leak.battery_energy < ls.battery_energy and ls.terms["leakage"] > 0
    lift, *rest = CYLINDERS.cylinders
    plain = replace(CYLINDERS, cylinders=(replace(lift, counterbalance=None), *rest))
    assert battery_boundary_baselines(t, f, v, plain, BATTERY)[1].battery_energy < ls.battery_energy


def test_bad_circuit_and_valve_values_are_rejected() -> None:
    """An efficiency above 1, a negative bleed flow or a valve on no chamber is one line naming the field."""
    with pytest.raises(InvalidInputError, match=r"hydraulics\.pump_efficiency"):
        CircuitParams(pump_efficiency=1.2)
    with pytest.raises(InvalidInputError, match=r"hydraulics\.bleed_flow"):
        CircuitParams(bleed_flow=-1.0)
    with pytest.raises(InvalidInputError, match=r"counterbalance\.side"):
        CounterbalanceValve("annulus", 3.0, 24.7e6)

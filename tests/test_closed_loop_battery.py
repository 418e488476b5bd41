"""The closed loop's battery energy: the logged DC energy through the battery, and the video's overlay of it."""

from __future__ import annotations

import re

import numpy as np
import pytest
from closed_loop_helper import synthetic_plan

from hiab_sim.crane.loader import load_crane
from hiab_sim.emla.battery import BatteryParams
from hiab_sim.env.closed_loop_battery import battery_entry, battery_notes, cumulative_battery_energy
from hiab_sim.env.rollout import ClosedLoopRun, run_closed_loop
from hiab_sim.env.validation import FPS, closed_loop_frame_times


@pytest.fixture(scope="module")
def run_and_battery() -> tuple[ClosedLoopRun, BatteryParams]:
    """A 1.5 s closed loop of the default crane on the real drive (emla_xs031.yaml's losses and battery)."""
    plan = synthetic_plan(load_crane("xs031"), emla="default")
    run, physics = run_closed_loop(plan)
    physics.free()
    return run, plan.emlas.battery


@pytest.mark.sim
def test_a_lossless_battery_passes_the_logged_dc_energy(run_and_battery: tuple[ClosedLoopRun, BatteryParams]) -> None:
    """With every efficiency 1 the battery energy is, at every logged time, the drives' DC energy the physics logged.

    The physics integrates each drive's DC input at its own steps (``cumulative_energy``); the battery
    path takes the step-mean powers through the bus and battery: two bookkeepings of one energy.
    """
    run, _ = run_and_battery
    lossless = BatteryParams(inverter_efficiency=1.0, discharge_efficiency=1.0, charge_efficiency=1.0)
    energy = cumulative_battery_energy(run, lossless)
    np.testing.assert_allclose(energy, run.cumulative_energy.sum(axis=1), rtol=1e-9, atol=1e-6)


@pytest.mark.sim
def test_the_battery_costs_its_discharge_loss(run_and_battery: tuple[ClosedLoopRun, BatteryParams]) -> None:
    """The real battery (eta_dis 0.975) delivers more than the bus takes, at most the drawn energy / eta_dis."""
    run, battery = run_and_battery
    energy = cumulative_battery_energy(run, battery)[-1]
    bus = np.diff(run.cumulative_energy.sum(axis=1))
    drawn, returned = bus[bus > 0].sum(), bus[bus < 0].sum()
    assert energy == pytest.approx(drawn / battery.discharge_efficiency + returned * battery.charge_efficiency)
    assert run.net_energy < energy <= drawn / battery.discharge_efficiency


@pytest.mark.sim
def test_the_overlays_last_number_is_the_reported_battery_energy(
    run_and_battery: tuple[ClosedLoopRun, BatteryParams],
) -> None:
    """Every frame states the cycle's total, ``simulation.json``'s ``battery_energy_J``; the last frame reaches it.

    The frames are the video's (:func:`hiab_sim.env.validation.closed_loop_frame_times`, over the run's duration):
    the first says 0, the last the total, and the frames between are 1 / ``FPS`` apart.
    """
    run, battery = run_and_battery
    reported = battery_entry(run, battery, None)["battery_energy_J"]
    assert reported is not None
    at = closed_loop_frame_times(float(run.time[-1]))
    notes = battery_notes(run, battery, at)
    pattern = re.compile(r"t = +([\d.]+) s   battery energy (-?[\d.]+) of (-?[\d.]+) kJ per cycle \(at the battery\)")
    parsed = [pattern.fullmatch(note) for note in notes]
    assert all(parsed)
    totals = {float(m.group(3)) for m in parsed if m}
    assert totals == {round(reported / 1e3, 3)}
    first, last = parsed[0], parsed[-1]
    assert first is not None and last is not None
    assert float(first.group(2)) == 0.0
    assert float(last.group(2)) == round(reported / 1e3, 3)
    assert float(last.group(1)) == pytest.approx(run.time[-1], abs=5e-3)
    assert np.all(np.diff(at)[:-1] == pytest.approx(1.0 / FPS)) and 0.0 < np.diff(at)[-1] <= 1.0 / FPS + 1e-12

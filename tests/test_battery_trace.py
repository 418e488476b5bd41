"""The trajectory's battery power: the playback's cumulative battery energy ends at the result's cycle figure."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hiab_sim.render.video import energy_notes
from hiab_sim.study import load_study
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.report.energy_section import cycle_battery_power, energy_report


def _trapezoid_by_hand(t: np.ndarray, p: np.ndarray) -> float:
    total = 0.0
    for k in range(len(t) - 1):
        total += 0.5 * (p[k] + p[k + 1]) * (t[k + 1] - t[k])
    return total


@pytest.mark.parametrize("with_duty", [True, False])
def test_battery_power_integrates_to_the_reported_cycle_battery_energy(with_duty: bool) -> None:
    """Hot windings and the duty's hold (default study), or no duty at all: the trace ends at the reported figure."""
    study = load_study("xs031_spiral")
    if not with_duty:
        study = replace(study, energy=replace(study.energy, duty=None))
    fine = TaskProblem(study, times=study.grid.fine_times(), tightened=False, cost_scale=1.0)
    ev = fine.evaluate(fine.initial_point(study.initial_lengths))
    energy = energy_report(fine, ev, ev).initial
    trace = cycle_battery_power(fine, ev)
    assert trace.shape == fine.times.shape
    cycle = _trapezoid_by_hand(fine.times, trace)
    if with_duty:
        assert energy.duty is not None
        assert cycle == pytest.approx(energy.duty.cycle_battery_energy_J, rel=1e-12)
        assert energy.duty.cycle_battery_energy_J < energy.battery_energy_J  # the rest adds its share
    else:
        assert energy.duty is None
        assert cycle == pytest.approx(energy.battery_energy_J, rel=1e-12)
    period = "duty period" if with_duty else "cycle"
    notes = energy_notes(fine.times, fine.times[[0, -1]], None, energy.battery_energy_J, period, trace)
    assert f"battery energy 0.000 of {cycle / 1e3:.3f} kJ per cycle (at the battery)" in notes[0]
    assert f"battery energy {cycle / 1e3:.3f} of {cycle / 1e3:.3f} kJ per cycle" in notes[1]


def test_hot_windings_make_the_cycle_trace_draw_more_than_the_cold_one() -> None:
    """The duty's fixed point raises R_s: the hot trace's cycle energy exceeds the cold operating points'."""
    study = load_study("xs031_spiral")
    cold_study = replace(study, energy=replace(study.energy, duty=None))
    hot = TaskProblem(study, times=study.grid.fine_times(), tightened=False, cost_scale=1.0)
    cold = TaskProblem(cold_study, times=study.grid.fine_times(), tightened=False, cost_scale=1.0)
    z = hot.initial_point(study.initial_lengths)
    e_hot = _trapezoid_by_hand(hot.times, cycle_battery_power(hot, hot.evaluate(z)))
    e_cold = _trapezoid_by_hand(cold.times, cycle_battery_power(cold, cold.evaluate(z)))
    assert e_hot > e_cold * 1.01


def test_caption_names_the_duty_period_figure_only_beside_a_cumulative_trace() -> None:
    """With a trace and a duty model the caption carries the per-period figure; a fixed figure stays in the note."""
    from types import SimpleNamespace

    from hiab_sim.render.video import design_texts

    time = np.linspace(0.0, 2.0, 5)
    data = SimpleNamespace(
        time=time, battery_energy_J={"optimal": 3000.0}, battery_period="duty period",
        battery_power={"optimal": np.full(5, 500.0)},
    )  # fmt: skip
    caption, notes = design_texts("optimal", "overlay", data, np.array([2.0]), None)
    assert caption == "optimal design: 3.00 kJ per duty period"
    assert notes[0].endswith("battery energy 1.000 of 1.000 kJ per cycle (at the battery)")
    old = SimpleNamespace(
        time=time, battery_energy_J={"initial": 0.0}, battery_period="duty period", battery_power=None
    )
    caption, notes = design_texts("initial", "overlay", old, np.array([2.0]), None)
    assert caption == "initial design, ghost"
    assert notes[0].endswith("battery energy 0.000 kJ per duty period (at the battery)")

"""A study without ``duty:`` holds no thermal limit: the summary says so where the optimum's motors exceed them.

Its result still reports each motor's RMS torque and winding temperature over back-to-back cycles; a
forestry crane's main-boom EMLA at 196 degC (limit 140) sat under "all limits hold" with nothing said.
The small excavator study (a 4 s move with 50 kg, no rest) is such a case: its boom motor runs hot.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from hiab_sim.results.read import read_result
from hiab_sim.study.report.summary import summary_lines


def test_summary_names_the_motors_over_their_thermal_limits_when_the_study_has_no_duty(excavator_result: Path) -> None:
    """Each motor over a limit in the result is named with its own numbers, in one line; a cool result has none."""
    r = read_result(excavator_result)
    assert r.energy is not None and r.energy.optimal.duty is None and r.energy.optimal.thermal is not None
    thermal = r.energy.optimal.thermal
    hot = {n: t for n, t in thermal.items() if t.torque_margin < 0.0 or t.temperature_margin_K < 0.0}
    assert hot  # the boom motor (back-to-back 4 s moves)
    lines = [line for line in summary_lines(r, excavator_result) if line.startswith("Thermal limits")]
    assert len(lines) == 1
    for name, t in hot.items():
        assert (
            f"{name} winding {t.peak_winding_temperature_C:.0f} degC (limit {t.max_winding_temperature_C:.0f})"
            in (lines[0])
        )
    cool = {n: dataclasses.replace(t, torque_margin=0.1, temperature_margin_K=1.0) for n, t in thermal.items()}
    optimal = dataclasses.replace(r.energy.optimal, thermal=cool)
    r_cool = dataclasses.replace(r, energy=dataclasses.replace(r.energy, optimal=optimal))
    assert not any(line.startswith("Thermal limits") for line in summary_lines(r_cool, excavator_result))

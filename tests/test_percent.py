"""Percent changes and savings keep the change's sign when the reference energy is negative."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from hiab_sim.docs_site.results_format import percent_change
from hiab_sim.percent import change_percent, saving_percent
from hiab_sim.study.report.summary import before_after

energies = st.floats(min_value=-1e7, max_value=1e7, allow_nan=False).filter(lambda e: abs(e) > 1e-3)


@given(energies, energies)
def test_a_saving_is_positive_exactly_when_the_energy_falls(reference: float, value: float) -> None:
    """Whatever the reference's sign: less energy after is a positive saving and a negative change."""
    saving, change = saving_percent(reference, value), change_percent(reference, value)
    assert np.sign(saving) == np.sign(reference - value)
    assert np.sign(change) == np.sign(value - reference)
    assert saving == pytest.approx(-change, rel=1e-12, abs=1e-12)


@given(energies, energies)
def test_a_change_applied_to_its_reference_gives_the_value_back(reference: float, value: float) -> None:
    """Adding |reference| change / 100 to the reference gives the value: the Pareto figure's second axis."""
    back = reference + abs(reference) * change_percent(reference, value) / 100.0
    assert back == pytest.approx(value, rel=1e-9, abs=1e-9 * abs(reference))


def test_a_regenerating_cycle_that_regenerates_more_reads_as_less_energy() -> None:
    """-85 J -> -87 J net is 2 J less energy: -2.35 %, not the +2.35 % of a division by the signed start."""
    assert saving_percent(-85.0, -87.0) == pytest.approx(200.0 / 85.0)
    assert percent_change(-85.0, -87.0) == "-2.35 %"
    assert before_after(-85.0, -87.0).endswith("(-2.35 %)")
    assert f"{saving_percent(-85.0, -85.0):.2f}" == "0.00"  # no saving prints without a sign


def test_arrays_are_taken_element_by_element() -> None:
    """A sweep's columns: each point against its own start, a negative start included."""
    start, optimum = np.array([100.0, -50.0]), np.array([90.0, -60.0])
    np.testing.assert_allclose(saving_percent(start, optimum), [10.0, 20.0])

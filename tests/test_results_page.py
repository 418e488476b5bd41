"""The results-page check: a page within the tolerance of a fresh run passes, a moved number or row fails."""

from __future__ import annotations

import pytest

from hiab_sim.docs_site.results_page import differences

BLOCK = "| quantity | value |\n|---|---|\n| battery energy | 5296.9 → 5162.9 J (-2.53 %) |\n| TCP error | 0.67 mm |"


def test_a_page_within_the_tolerance_passes() -> None:
    """Round-off in the last digit (5162.9 -> 5163.0 J) and 0.1 % moves are not stale."""
    assert differences(BLOCK, BLOCK.replace("5162.9", "5163.0")) == []
    assert differences(BLOCK, BLOCK.replace("5296.9", "5302.0")) == []


@pytest.mark.parametrize(
    ("old", "new"),
    [("5162.9", "5190.0"), ("0.67 mm", "0.71 mm"), ("battery energy", "net energy"), ("| TCP error | 0.67 mm |", "")],
)
def test_a_stale_page_fails(old: str, new: str) -> None:
    """A number 0.5 % away, another label or a missing row makes the page stale."""
    assert differences(BLOCK, BLOCK.replace(old, new).strip()) != []

"""Sweep summary figures: failed points are drawn as failed, off the data's scale, never as values."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hiab_sim.sweep import figures


def test_failed_points_sit_on_a_strip_outside_the_axes_at_their_own_x(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A failed point (no energy) is a cross above the axes (axes fraction > 1) at its x, inside the x range."""
    frame = pd.DataFrame(
        {
            "gear": [3.0, 4.0, 5.0, 6.0],
            "status": ["ok", "ok", "ok", "failed"],
            "net_energy_saved_percent": [2.0, 3.0, 4.0, np.nan],
            "start_net_energy_J": [4.2e3, 4.1e3, 4.0e3, np.nan],
            "opt_net_energy_J": [4e3, 3.9e3, 3.8e3, np.nan],
        }
    )
    drawn = []
    monkeypatch.setattr(figures, "save_png", lambda fig, path: drawn.append(fig) or path)
    figures.summary_figures(frame, ["gear"], tmp_path, "test")
    (fig,) = drawn
    for ax in fig.axes:
        failed = [c for c in ax.collections if c.get_label().startswith("failed")]
        assert len(failed) == 1
        (x, y) = failed[0].get_offsets()[0]
        assert x == 6.0 and y > 1.0  # y in axes fraction: above the data, not a value
        assert failed[0].get_offset_transform() == ax.get_xaxis_transform()
        low, high = ax.get_xlim()
        assert low < 3.0 and 6.0 < high


@pytest.mark.parametrize(
    ("message", "words"),
    [
        (
            "InfeasibleStudyError: no feasible point within the bounds (feasibility phase from start 0, least "
            "violation at Xi = [0.8, 0.04] m): tracking.position.x_tcp >= -band at t = 0.75 s: the TCP leaves its "
            "tracking band by 1 % of the band",
            "the TCP leaves its tracking band by 1 % of the band",
        ),
        (
            "InfeasibleStudyError: no feasible point (least violation at Xi = [1.05] m): brake.lift holding torque "
            "violated by 27.4 %",
            "lift brake holding torque violated by 27.4 %",
        ),
        ("SolverError: Iteration limit reached", "Iteration limit reached"),
    ],
)
def test_a_failed_cell_says_why_in_words(message: str, words: str) -> None:
    """The saving map's failed cell names the limit its feasibility phase broke least, without the row's name."""
    assert figures.failed_reason(message) == words

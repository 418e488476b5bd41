"""A Hypothesis strategy for the pick-and-place references the reference tests draw."""

from __future__ import annotations

from typing import Any

from hypothesis import strategies as st

from hiab_sim.study.references.kinds import PickAndPlace


@st.composite
def pick_and_place_tasks(
    draw: Any, rise: float = 2.0, shortest_move: float = 3.0, longest_dwell: float = 3.0
) -> PickAndPlace:
    """A pick-and-place in the XS 031's reach.

    Its apex up to ``rise`` [m] above the higher end point, a move of ``shortest_move`` to 16 s, dwells up to
    ``longest_dwell`` [s].
    """
    pick = draw(st.tuples(st.floats(1.2, 2.2), st.floats(-1.6, -0.4)))
    place = draw(st.tuples(st.floats(2.6, 4.0), st.floats(-1.0, 1.0)))
    clearance = max(pick[1], place[1]) + draw(st.floats(0.05, rise))
    telescope = draw(st.tuples(st.floats(0.0, 1.1), st.floats(0.0, 1.1)))
    move_time = draw(st.floats(shortest_move, 16.0))
    dwell = draw(st.tuples(st.floats(0.0, longest_dwell), st.floats(0.0, longest_dwell)))
    return PickAndPlace(pick, place, clearance, telescope, move_time, dwell)

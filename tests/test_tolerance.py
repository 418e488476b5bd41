"""Manufacturing tolerance: rounding, the crane's checks as margins, corner checks and first-order robust margins."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane.description import ChainLengths, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.crane.mechanism import check_lengths
from hiab_sim.crane.mounting import built_space, polygon_margins
from hiab_sim.crane.tolerance import (
    check_tolerance,
    robust_margins,
    round_lengths,
    tolerance_designs,
    working_range_margins,
)
from hiab_sim.errors import InvalidInputError

CRANE = load_crane("xs031")
lengths_strategy = st.tuples(
    st.floats(0.8, 1.4), st.floats(0.02, 0.3), st.floats(0.55, 1.0), st.floats(0.8, 1.4), st.floats(0.02, 0.3),
    st.floats(0.55, 1.0),
)  # fmt: skip


@settings(max_examples=100, deadline=None)
@given(st.lists(st.floats(0.01, 2.0), min_size=6, max_size=6), st.sampled_from([1e-3, 5e-4, 1e-2]))
def test_rounding_lands_on_the_tolerance_grid_within_half_a_step(values: list[float], tolerance: float) -> None:
    """A rounded length is a multiple of the tolerance, within tolerance/2 of the input; rounding is idempotent."""
    lengths = LinkLengths.from_array(values)
    rounded = round_lengths(lengths, tolerance).as_array()
    steps = rounded / tolerance
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-9)
    assert np.all(np.abs(rounded - lengths.as_array()) <= tolerance / 2 + 1e-12)
    np.testing.assert_array_equal(round_lengths(LinkLengths.from_array(rounded), tolerance).as_array(), rounded)


@settings(max_examples=200, deadline=None)
@given(lengths_strategy)
def test_margins_agree_with_the_cranes_own_check(values: tuple[float, ...]) -> None:
    """Every working-range margin is >= 0 exactly when check_lengths accepts the design."""
    lengths = LinkLengths.from_array(values)
    margins = working_range_margins(CRANE, lengths).values
    if np.min(np.abs(margins)) < 1e-9:
        return  # on a boundary: the two may round differently
    try:
        check_lengths(CRANE, lengths)
        accepted = True
    except InvalidInputError:
        accepted = False
    assert accepted == bool(np.all(margins >= 0.0))


def test_the_built_crane_rounded_to_a_millimetre_fails_both_checks() -> None:
    """The built crane's lengths rounded to 1 mm leave the stroke at the low end: both checks say so."""
    rounded = round_lengths(CRANE.default_lengths)
    margins = working_range_margins(CRANE, rounded)
    assert margins.worst()[1] < 0.0
    with pytest.raises(InvalidInputError, match="joint_range"):
        check_lengths(CRANE, rounded)


@settings(max_examples=30, deadline=None)
@given(lengths_strategy)
def test_working_range_jacobian_matches_central_differences(values: tuple[float, ...]) -> None:
    """dg/dXi of the working-range margins equals central differences to 1e-8."""
    x = np.asarray(values)
    margins = working_range_margins(CRANE, LinkLengths.from_array(x))
    h = 1e-6
    fd = np.column_stack(
        [
            (
                working_range_margins(CRANE, LinkLengths.from_array(x + h * e)).values
                - working_range_margins(CRANE, LinkLengths.from_array(x - h * e)).values
            )
            / (2 * h)
            for e in np.eye(6)
        ]
    )
    np.testing.assert_allclose(margins.jacobian, fd, atol=1e-8)


def test_corners_cover_the_box_and_the_rounded_design() -> None:
    """66 designs: nominal, rounded, and 64 distinct corners each exactly +-tolerance from nominal in every entry."""
    lengths = LinkLengths.from_array([1.0071, 0.0853, 0.7457, 1.1321, 0.0851, 0.7449])
    labels, designs = tolerance_designs(lengths, 1e-3)
    assert labels[:2] == ("nominal", "rounded") and len(set(labels)) == 66
    np.testing.assert_allclose(np.abs(designs[2:] - designs[0]), 1e-3, atol=1e-15)
    assert len({tuple(np.sign(d - designs[0])) for d in designs[2:]}) == 64
    np.testing.assert_allclose(designs[1], round_lengths(lengths).as_array())


def test_robust_margin_is_the_exact_corner_minimum_for_rows_linear_in_xi() -> None:
    """For polygon rows and Lc - stroke (linear in Xi), g - |dg/dXi| t equals the minimum over the 64 corners."""
    space = built_space(CRANE)
    lengths = LinkLengths.from_array([1.05, 0.1, 0.75, 1.1, 0.1, 0.76])
    t = 2e-3
    check = check_tolerance(lambda xi: polygon_margins(space, CRANE, xi), lengths, t)
    np.testing.assert_allclose(robust_margins(polygon_margins(space, CRANE, lengths), t), check.margins[2:].min(axis=0))
    wr = check_tolerance(lambda xi: working_range_margins(CRANE, xi), lengths, t)
    robust = robust_margins(working_range_margins(CRANE, lengths), t)
    linear = [i for i, n in enumerate(wr.names) if "Lc - stroke" in n or n.endswith("> 0")]
    np.testing.assert_allclose(robust[linear], wr.margins[2:, linear].min(axis=0), atol=1e-15)
    # the stroke rows are curved in L only: first order errs by at most t^2 / (2 s), s > 0.3 m
    np.testing.assert_allclose(robust, wr.margins[2:].min(axis=0), atol=t**2 / 0.6)


def test_a_design_with_stroke_slack_passes_and_a_tight_one_fails_at_the_predicted_corner() -> None:
    """With a 10 mm longer tilt stroke, the centred design holds for +-1 mm; shifting x0 to the edge fails."""
    tilt = replace(CRANE.tilt, stroke=CRANE.tilt.stroke + 0.01)
    crane = replace(CRANE, tilt=tilt)
    g = lambda xi: working_range_margins(crane, xi)  # noqa: E731
    base = LinkLengths(ChainLengths(CRANE.lift.default_lengths.L, 0.065, 0.745), ChainLengths(1.1, 0.1, 0.75))
    m = g(base)
    low, up = (m.values[m.names.index(f"tilt.x {w}")] for w in (">= 0 at the low end", "<= stroke at the up end"))
    centred = replace(base, tilt=replace(base.tilt, Lc0=base.tilt.Lc0 + 0.5 * (low - up)))
    ok = check_tolerance(g, centred)
    assert ok.ok, ok.summary()
    tight = replace(centred, tilt=replace(centred.tilt, Lc0=centred.tilt.Lc0 + 0.004))
    check = check_tolerance(g, tight)
    label, name, value = check.worst()
    assert not check.ok and name == "tilt.x >= 0 at the low end" and value < 0.0
    # x = s(L) - Lc0 - Lc is least at L - t (ds/dL > 0 at the low end), Lc0 + t, Lc + t
    assert label.startswith("corner ") and label[-3:] == "-++"


def test_bad_tolerance_is_rejected_with_the_field() -> None:
    """A tolerance that is not a positive finite length is a one-line error naming the field."""
    with pytest.raises(InvalidInputError, match="tolerance"):
        round_lengths(CRANE.default_lengths, 0.0)


def test_design_margins_report_the_worst_of_both_checks() -> None:
    """With a mounting space, g(Xi) holds the working-range and mounting rows; the worst is the worse of the two."""
    from hiab_sim.crane.mounting import built_space, mounting_margins
    from hiab_sim.crane.tolerance import design_margins

    lengths = LinkLengths.from_array([1.25, 0.3, 0.7317, 1.24, 0.3, 0.6374])
    both = design_margins(CRANE, built_space(CRANE))(lengths)
    parts = [working_range_margins(CRANE, lengths), mounting_margins(built_space(CRANE), CRANE, lengths)]
    assert both.names == parts[0].names + parts[1].names
    assert both.worst()[1] == min(p.worst()[1] for p in parts)
    assert design_margins(CRANE)(lengths).names == parts[0].names

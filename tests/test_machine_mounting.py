"""A machine file's mounting space: the crane form's rows on the XS 031, forward kinematics, point-in-polygon, FD.

The machine form (:mod:`hiab_sim.machine.mounting`) is written on the generic description; the
crane form (:mod:`hiab_sim.crane.mounting`) on the crane file's closed-form chains. On the XS 031
both must give the same rows; the swept-link row must be the distance a forward-kinematics sweep
of the whole machine measures; the polygon rows must say "inside" exactly where a point-in-polygon
test does; every Jacobian must match central differences.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from machine_result_helper import EXCAVATOR_STUDY, joint_csv
from matplotlib.path import Path as MplPath

from hiab_sim.crane.description import LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.crane.mounting import built_space, mounting_margins
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine.mounting import MachineMountingSpace, machine_mounting_margins, moved_pivots
from hiab_sim.study.analysis.buildable import ROBUST_CLEARANCE
from hiab_sim.study.spec.study_file import load_study

REPO = Path(__file__).resolve().parents[1]
XS031 = load_machine("xs031")
EXACT = load_machine("exact")
CRANE = load_crane("xs031")
CRANE_SPACE = built_space(CRANE)
#: The crane form's built space in the machine form: the same polygons on the same pivots and frames.
XS031_SPACE = MachineMountingSpace((("lift", "base", CRANE_SPACE.lift or ()), ("tilt", "base", CRANE_SPACE.tilt or ())))
#: The crane form's labels of the tilt base pivot's pins and the machine form's for the same pins.
SAME_PINS = {"lift boom hinge": "theta1 hinge", "lift rod-end pivot": "lift end pivot"}


def _design(machine: object, unit: list[float]) -> np.ndarray:
    low, high = machine.design_bounds()  # type: ignore[attr-defined]
    return low + np.asarray(unit[: len(low)]) * (high - low)


UNITS = st.lists(st.floats(0.0, 1.0), min_size=9, max_size=9)


@settings(max_examples=30, deadline=None)
@given(UNITS)
def test_xs031_machine_form_gives_the_crane_forms_rows(unit: list[float]) -> None:
    """Polygons to round-off, the same pins, the tilt boom's sweep; the lift boom's sweep also passes its tilt bracket.

    The machine form's lift-boom centre line runs through every pin on the boom, the tilt cylinder's
    base pivot included; the crane form's runs hinge -> rod end -> tilt hinge. So the machine row is
    never larger, and equal where the closest point is not near that bracket.
    """
    values = _design(XS031, unit)
    crane = mounting_margins(CRANE_SPACE, CRANE, LinkLengths.from_array(values))
    machine = machine_mounting_margins(XS031_SPACE, XS031, values)
    assert machine.names[:8] == crane.names[:8]  # the polygon rows, named alike
    assert np.allclose(machine.values[:8], crane.values[:8], rtol=0.0, atol=1e-14)
    assert np.allclose(machine.jacobian[:8], crane.jacobian[:8], rtol=0.0, atol=1e-14)
    by_name = dict(zip(machine.names, machine.values, strict=True))
    for label, theirs in SAME_PINS.items():
        mine = by_name[f"mounting.tilt base pivot clear of the {theirs}"]
        assert mine == pytest.approx(crane.values[crane.names.index(f"mounting.tilt base pivot clear of the {label}")])
    tilt_sweep = "mounting.tilt base pivot clear of the {} over its working range"
    assert by_name[tilt_sweep.format("tilt_boom")] == pytest.approx(
        crane.values[crane.names.index(tilt_sweep.format("tilt boom"))], abs=1e-12
    )
    lift_sweep = "mounting.lift base pivot clear of the {} over its working range"
    assert (
        by_name[lift_sweep.format("lift_boom")]
        <= crane.values[crane.names.index(lift_sweep.format("lift boom"))] + 1e-12
    )
    assert len(machine.names) == len(crane.names)


@settings(max_examples=25, deadline=None)
@given(UNITS, st.sampled_from(["xs031", "exact"]))
def test_mounting_jacobian_matches_central_differences(unit: list[float], name: str) -> None:
    """dg/dv of every row (polygons, pins, swept links) equals central differences to 1e-7 per m."""
    machine = XS031 if name == "xs031" else EXACT
    space = XS031_SPACE if name == "xs031" else MachineMountingSpace(clearance=0.04, samples=61)
    values = _design(machine, unit)
    rows = machine_mounting_margins(space, machine, values)
    h = 1e-6
    for k in range(len(values)):
        step = np.zeros(len(values))
        step[k] = h
        up = machine_mounting_margins(space, machine, values + step).values
        down = machine_mounting_margins(space, machine, values - step).values
        assert np.max(np.abs((up - down) / (2 * h) - rows.jacobian[:, k])) < 1e-7, f"column {k}"


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    t = np.clip(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * (b - a))))


@pytest.mark.parametrize("chain", ["boom", "arm", "bucket"])
def test_swept_row_is_the_distance_a_forward_kinematics_sweep_measures(chain: str) -> None:
    """In the world: the base pivot and the driven link's centre line posed by forward kinematics at every sample.

    The excavator's moved base pivots sit on the parent of the link their chain turns; the row is
    the smallest distance from the pivot to the link's hinge -> pins polyline over its joint range.
    """
    samples = 41
    space = MachineMountingSpace(clearance=0.05, samples=samples)
    values = EXACT.design_values() + 0.01 * np.sin(np.arange(len(EXACT.decision_variables)))
    rows = machine_mounting_margins(space, EXACT, values)
    designed = EXACT.with_design(values, check_bounds=False)
    c = designed.chain(chain)
    driven = designed.joint_link(c.joint)
    base = c.pivot("base")
    on_link = [p.xy for other in designed.chains for p in other.pivots if p.link == driven.name]
    on_link += [np.asarray(k.joint_frame.position[:2]) for k in designed.links if k.parent == driven.name]
    points = [np.zeros(2), *sorted(on_link, key=lambda xy: float(np.hypot(*xy)))]
    mid = np.array([0.5 * sum(link.joint_range) for link in designed.links if link.parent is not None])
    j = designed.joint_names.index(c.joint)
    best = np.inf
    for q in np.linspace(*driven.joint_range, samples):
        pose = mid.copy()
        pose[j] = q
        frames = forward_kinematics(designed, pose)
        p = frames.point(base.link, [*base.xy, 0.0])[:2]
        line = [frames.point(driven.name, [*xy, 0.0])[:2] for xy in points]
        best = min(best, *(_segment_distance(p, a, b) for a, b in itertools.pairwise(line)))
    row = f"mounting.{chain} base pivot clear of the {driven.name} over its working range"
    assert rows.values[rows.names.index(row)] + space.clearance == pytest.approx(best, abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.floats(-0.06, 0.06), st.floats(-0.06, 0.06), st.floats(0.01, 0.05), st.floats(0.0, 3.0))
def test_polygon_rows_say_inside_where_a_point_in_polygon_test_does(
    dx: float, dy: float, r: float, turn: float
) -> None:
    """The bucket's base pin moves in x and y (Gx, Gy): all edge rows >= 0 exactly when matplotlib finds it inside."""
    keys = EXACT.variable_keys
    values = EXACT.design_values()
    centre = values[[keys.index("bucket.Gx"), keys.index("bucket.Gy")]]
    angles = turn + np.linspace(0.0, 2.0 * np.pi, 6, endpoint=False)  # a hexagon of radius r, counter-clockwise
    hexagon = tuple((float(centre[0] + r * np.cos(a)), float(centre[1] + r * np.sin(a))) for a in angles)
    values[keys.index("bucket.Gx")] += dx
    values[keys.index("bucket.Gy")] += dy
    rows = machine_mounting_margins(MachineMountingSpace((("bucket", "base", hexagon),)), EXACT, values)
    edges = rows.values[[i for i, n in enumerate(rows.names) if " inside edge " in n]]
    assert len(edges) == 6
    if abs(float(np.min(edges))) > 1e-9:  # not on an edge, where the two tests may round apart
        inside = MplPath(np.asarray(hexagon)).contains_point(centre + np.array([dx, dy]))
        assert bool(np.all(edges > 0.0)) == inside


def test_moved_pivots_are_those_a_decision_variable_moves() -> None:
    """The XS 031's two base pivots (L), the excavator's boom, arm (L) and bucket (Gx, Gy) base pivots."""
    assert moved_pivots(XS031) == [("lift", "base"), ("tilt", "base")]
    assert moved_pivots(EXACT) == [("boom", "base"), ("arm", "base"), ("bucket", "base")]


#: A counter-clockwise triangle [m].
TRI = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]


def _study_with(folder: Path, mounting: object) -> Path:
    joint_csv(folder / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump({**EXCAVATOR_STUDY, "mounting": mounting}), encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("mounting", "error", "message"),
    [
        ({"lift": {"base": TRI}}, ConfigError, r"mounting: unknown key\(s\) \['lift'\]"),
        ({"boom": {"hinge": TRI}}, ConfigError, r"mounting\.boom: unknown key\(s\) \['hinge'\]"),
        ({"boom": {"end": TRI}}, InvalidInputError, r"mounting\.boom\.end.*moved pivots: boom\.base"),
        ({"bucket": {"base": TRI[::-1]}}, InvalidInputError, r"mounting\.bucket\.base.*counter-clockwise"),
        ({"bucket": {"base": [*TRI[:2], [0.4, 0.1], TRI[2]]}}, InvalidInputError, r"mounting\.bucket\.base.*convex"),
        ({"bucket": {"base": [[float("nan"), 0.0], *TRI[1:]]}}, InvalidInputError, r"mounting\.bucket\.base.*finite"),
        ({"bucket": {"base": TRI[:2]}}, InvalidInputError, r"mounting\.bucket\.base.*at least 3"),
        ({"bucket": {"base": None}}, ConfigError, r"mounting\.bucket\.base: expected a list"),
        ({"clearance": -0.01}, (ConfigError, InvalidInputError), r"mounting\.clearance"),
        ({"samples": 1}, InvalidInputError, r"mounting\.samples"),
    ],
)
def test_bad_machine_mounting_is_one_line_naming_the_field(
    tmp_path: Path, mounting: object, error: type[Exception], message: str
) -> None:
    with pytest.raises(error, match=message) as raised:
        load_study(_study_with(tmp_path, mounting))
    assert "\n" not in str(raised.value)


def test_bad_machine_mounting_exits_2_and_writes_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from hiab_sim.cli import main

    study = _study_with(tmp_path, {"boom": {"end": [[0, 0], [1, 0], [0, 1]]}})
    assert main(["optimize", str(study), "--out", str(tmp_path / "run"), "--no-figures"]) == 2
    err = capsys.readouterr().err
    assert "mounting.boom.end" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "run").exists()


def _xs031_mounting_study_in_machine_form(folder: Path) -> Path:
    """``xs031_spiral_mounting`` on the XS 031's machine file: its polygons under ``<chain>: {base: ...}``."""
    top = yaml.safe_load((REPO / "optimize" / "xs031_spiral_mounting.yaml").read_text(encoding="utf-8"))
    del top["crane"]
    top["bounds"] = {k: v for k, v in top["bounds"].items() if k not in ("lift", "tilt", "triangle_margin_deg")}
    mounting = top["mounting"]
    top.update(machine="xs031", tracked=["xt2"])
    top["mounting"] = {"lift": {"base": mounting["lift"]}, "tilt": {"base": mounting["tilt"]}, "clearance": 0.05}
    path = folder / "xs031_spiral_mounting_machine.yaml"
    path.write_text(yaml.safe_dump(top), encoding="utf-8")
    return path


@pytest.mark.e2e
def test_mounting_study_on_the_machine_file_reaches_the_crane_files_optimum(tmp_path: Path) -> None:
    """``xs031_spiral_mounting`` both ways: the same optimum (a polygon edge binding), iterations and energy."""
    from hiab_sim.study.run import run_study

    crane_study = load_study(REPO / "optimize" / "xs031_spiral_mounting.yaml")
    machine_study = load_study(_xs031_mounting_study_in_machine_form(tmp_path))
    assert isinstance(machine_study.mounting, MachineMountingSpace)
    crane = run_study(crane_study, tmp_path / "crane", progress=None, figures=False).result
    machine = run_study(machine_study, tmp_path / "machine", progress=None, figures=False).result
    assert np.max(np.abs(crane.optimal.lengths.as_array() - machine.optimal.lengths.as_array())) < 1e-8
    assert machine.solver.iterations == crane.solver.iterations
    assert machine.optimal.net_electrical_energy_J == pytest.approx(crane.optimal.net_electrical_energy_J, rel=1e-9)
    assert crane.buildable is not None and machine.buildable is not None
    assert machine.buildable.lengths.as_array() == pytest.approx(crane.buildable.lengths.as_array(), abs=1e-12)
    # the binding row of the +-1 mm box is the same polygon edge, held with the same robust clearance
    assert machine.buildable.tolerance_check.worst.startswith("mounting.lift base pivot inside edge 3")
    assert crane.buildable.tolerance_check.worst.startswith("mounting.lift base pivot inside edge 3")
    assert machine.buildable.tolerance_check.margin == pytest.approx(crane.buildable.tolerance_check.margin, abs=1e-12)
    # at the same corner of the box, named the same way: its signs in the decision variables' order
    assert machine.buildable.tolerance_check.worst == crane.buildable.tolerance_check.worst
    assert " at the corner " in crane.buildable.tolerance_check.worst


#: A 0.1 m square around the excavator's bucket cylinder base pin (arm frame, m): the tutorial's example.
BUCKET_BOX = [[-0.184, 0.270], [-0.084, 0.270], [-0.084, 0.370], [-0.184, 0.370]]


@pytest.mark.e2e
def test_a_binding_polygon_holds_the_excavators_optimum_inside_it_to_the_tolerance(tmp_path: Path) -> None:
    """Free, the small excavator study moves the bucket pin out of the box; with it, onto the box less 1 mm.

    The robust rows hold every design within +-``build.tolerance`` (1 mm) inside the polygon, so the
    optimum sits 1 mm (and the robust rows' 1e-6 m clearance) inside the two binding edges; the
    constrained optimum costs no less; the rounded design's rows hold (computed here from the
    machine file, apart from the report's check).
    """
    from hiab_sim.study.run import run_study

    free = run_study(load_study(_study_with(tmp_path, None)), tmp_path / "free", progress=None, figures=False).result
    path = _study_with(tmp_path, {"bucket": {"base": BUCKET_BOX}, "clearance": 0.05})
    boxed = run_study(load_study(path), tmp_path / "boxed", progress=None, figures=False).result
    keys = list(boxed.optimal.lengths.names)
    gx, gy = keys.index("bucket.Gx"), keys.index("bucket.Gy")
    x_free, x_box = free.optimal.lengths.as_array(), boxed.optimal.lengths.as_array()
    assert x_free[gx] > -0.084 and x_free[gy] < 0.270  # outside the box where it is free
    inset = 1e-3 + ROBUST_CLEARANCE  # the tolerance and the robust rows' own clearance beyond it
    assert x_box[gx] == pytest.approx(-0.084 - inset, abs=1e-9) and x_box[gy] == pytest.approx(0.270 + inset, abs=1e-9)
    assert boxed.optimal.collocation_cost_W2s >= free.optimal.collocation_cost_W2s * (1.0 - 1e-9)
    assert boxed.buildable is not None and boxed.buildable.tolerance_check.passed
    space = MachineMountingSpace((("bucket", "base", tuple((x, y) for x, y in BUCKET_BOX)),))
    rounded = machine_mounting_margins(space, EXACT, boxed.buildable.lengths.as_array())
    assert rounded.worst()[1] >= 0.0

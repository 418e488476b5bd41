"""Buildable designs: robust rows, the rounded design, the feasibility phase and KKT sensitivities."""

from __future__ import annotations

import dataclasses
import itertools
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.crane.description import LinkLengths
from hiab_sim.crane.mechanism import check_lengths, joint_to_stroke
from hiab_sim.crane.tolerance import buildable_crane
from hiab_sim.resources import shipped
from hiab_sim.study.analysis.buildable import RobustXi, replace_lengths, rounded_design
from hiab_sim.study.analysis.sensitivity import sensitivity
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.solvers.feasibility import feasible_start
from hiab_sim.study.solvers.slsqp import solve
from hiab_sim.study.spec.study_file import Study, study_from_dict

#: End-to-end runs of whole studies and commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def solved() -> tuple[StudyProblem, np.ndarray]:
    """The small study solved from the built crane."""
    study = study_from_dict(small_study(), "small.yaml")
    problem = StudyProblem(study)
    result = solve(problem, study.initial_lengths, progress=None)
    return problem, result.z


def test_every_design_within_the_tolerance_serves_the_buildable_range(
    solved: tuple[StudyProblem, np.ndarray],
) -> None:
    """Each of the 64 corners Xi +- t of the optimum passes the crane's own check over the buildable range."""
    problem, z = solved
    study = problem.study
    short = buildable_crane(study.crane, study.build.stroke_margin)
    xi = problem.unpack(z)[0].as_array()
    t = study.build.tolerance
    for signs in itertools.product((-1.0, 1.0), repeat=6):
        check_lengths(short, LinkLengths.from_array(xi + t * np.array(signs)))  # raises if a stroke leaves [0, stroke]
    rounded = rounded_design(
        LinkLengths.from_array(xi), t, np.asarray(study.bounds.xi_low), np.asarray(study.bounds.xi_up)
    )
    assert np.all(np.abs(rounded.as_array() - xi) <= t / 2 + 1e-12)
    check_lengths(short, rounded)


def test_robust_rows_match_the_worst_corner_to_second_order(solved: tuple[StudyProblem, np.ndarray]) -> None:
    """G - |dg/dXi| t of the buildable-range rows equals the least margin over the 64 corners within t^2 / s."""
    problem, z = solved
    block = next(b.block for b in problem.blocks if isinstance(b.block, RobustXi) and b.block.name == "buildable_range")
    ev = problem.evaluate(z).tasks[0]
    robust = block.values(ev) + block.clearance()
    t = problem.study.build.tolerance
    xi = ev.lengths.as_array()
    corners = []
    for signs in itertools.product((-1.0, 1.0), repeat=6):
        lengths = LinkLengths.from_array(xi + t * np.array(signs))
        cols = []  # independent: the stroke from the chain trigonometry at the range ends, scaled by 0.1 m
        for theta in (np.array([w[0] for w in block.inner.working]), np.array([w[1] for w in block.inner.working])):
            for j, chain in enumerate(problem.study.crane.chains):
                x = float(joint_to_stroke(chain, getattr(lengths, chain.name), theta[j]))
                cols += [x, getattr(lengths, chain.name).Lc - x, chain.stroke - x]
        corners.append(np.array(cols) / 0.1)
    worst = np.min(corners, axis=0)
    np.testing.assert_allclose(robust, worst, atol=1e-5)  # t^2 / (2 s 0.1 m) ~ 5e-6 scaled


def _xi_central_differences(block: Any, ev: Any, h: float = 1e-6) -> np.ndarray:
    """Central differences (step ``h`` [m]) of a block's row values over the six link lengths, one column each."""
    xi = ev.lengths.as_array()
    return np.column_stack(
        [
            (block.values(replace_lengths(ev, xi + h * e)) - block.values(replace_lengths(ev, xi - h * e))) / (2 * h)
            for e in np.eye(6)
        ]
    )


def test_robust_jacobian_matches_finite_differences(solved: tuple[StudyProblem, np.ndarray]) -> None:
    """The robust rows' Jacobian (with the curvature term) agrees with central differences of their values."""
    problem, z = solved
    block = next(b.block for b in problem.blocks if isinstance(b.block, RobustXi))
    ev = problem.evaluate(z).tasks[0]
    jac = block.jacobian(ev, None).dxi  # type: ignore[arg-type]
    np.testing.assert_allclose(jac, _xi_central_differences(block, ev), atol=1e-6)


def test_multipliers_predict_the_cost_change_of_a_bound_move(solved: tuple[StudyProblem, np.ndarray]) -> None:
    """Each active Xi bound's multiplier predicts the re-solved cost change of a 1 mm move within 5 %."""
    problem, z = solved
    study = problem.study
    sens = sensitivity(problem, z)
    bounds = [m for m in sens.multipliers if m.constraint.startswith("bound ")]
    assert bounds, "the small study's optimum has active length bounds"
    f0 = problem.evaluate(z).cost
    names = ("lift.L", "lift.Lc0", "lift.Lc", "tilt.L", "tilt.Lc0", "tilt.Lc")
    for m in bounds:
        _, name, side, *_ = m.constraint.split()
        k = names.index(name)
        low, up = list(study.bounds.xi_low), list(study.bounds.xi_up)
        if side == "up":
            up[k] += 1e-3
        else:
            low[k] -= 1e-3
        moved = dataclasses.replace(study, bounds=dataclasses.replace(study.bounds, xi_low=tuple(low), xi_up=tuple(up)))
        p2 = StudyProblem(moved, cost_scales=[problem.problems[0].cost_scale])
        z2 = solve(p2, study.initial_lengths, progress=None, z0=z).z
        actual = f0 - p2.evaluate(z2).cost
        assert actual == pytest.approx(m.objective_decrease_per_unit, rel=0.05), m.constraint


@pytest.mark.parametrize("chain", ["lift", "tilt"])
def test_stroke_row_multipliers_predict_a_longer_stroke(solved: tuple[StudyProblem, np.ndarray], chain: str) -> None:
    """A 1 mm longer stroke moves each active 'x <= stroke' row by 1 mm: the multipliers predict the re-solve in 5 %.

    The rows are the working range's and the buildable range's at the up end (the lift's buildable
    range ends at its toggle margin, not at its stroke, so its row moves with the stroke too).
    """
    problem, z = solved
    study = problem.study
    rows = [
        m for m in sensitivity(problem, z).multipliers if m.constraint.endswith(f"{chain}.x <= stroke at the up end")
    ]
    assert rows, f"an {chain} stroke row is active at the small study's optimum"
    predicted = sum(m.objective_decrease_per_unit for m in rows)
    old = getattr(study.crane, chain)
    crane = dataclasses.replace(study.crane, **{chain: dataclasses.replace(old, stroke=old.stroke + 1e-3)})
    longer = dataclasses.replace(study, crane_description=crane)
    p2 = StudyProblem(longer, cost_scales=[problem.problems[0].cost_scale])
    z2 = solve(p2, study.initial_lengths, progress=None, z0=z).z
    actual = problem.evaluate(z).cost - p2.evaluate(z2).cost
    assert actual == pytest.approx(predicted, rel=0.05), [m.constraint for m in rows]


def test_envelope_multiplier_predicts_a_slightly_stronger_motor(tmp_path: Path) -> None:
    """With the lift's peak-torque row binding, its per-% multiplier predicts a re-solve with 1e-5 more peak torque.

    460 kg on the small study with the envelope margin raised to 0.1 makes the row bind at the
    optimum (the start goes through the feasibility phase). The unconstrained optimum lies close,
    so the prediction is first order only for small moves (0.01 % already saturates by 9 %).
    """

    def study_with(peak_scale: float) -> Study:
        document = yaml.safe_load(shipped("emla", "paper").read_text())  # the payload is sized for the paper model
        peak = document["pmsm"]["peak_torque"]
        value = float(peak["value"] if isinstance(peak, dict) else peak)
        document["actuators"]["lift"].setdefault("pmsm", {})["peak_torque"] = value * peak_scale
        emla = tmp_path / f"emla_{peak_scale}.yaml"
        emla.write_text(yaml.safe_dump(document))
        mapping = small_study(payload=460.0, emla=str(emla))
        mapping["bounds"]["envelope_margin"] = 0.1
        return study_from_dict(mapping, "small.yaml")

    problem = StudyProblem(study_with(1.0))
    z0, phase = feasible_start(problem, problem.initial_point(problem.study.initial_lengths))
    assert phase is not None  # the raised margin makes the built crane's start infeasible
    z = solve(problem, problem.unpack(z0)[0], progress=None, z0=z0).z
    rows = [m for m in sensitivity(problem, z).multipliers if m.constraint.startswith("envelope.lift.peak_torque")]
    assert len(rows) == 1 and rows[0].unit == "%"
    step = 1e-5  # relative: 0.001 %
    stronger_problem = StudyProblem(study_with(1.0 + step), cost_scales=[problem.problems[0].cost_scale])
    z2 = solve(stronger_problem, problem.unpack(z)[0], progress=None, z0=z).z
    actual = problem.evaluate(z).cost - stronger_problem.evaluate(z2).cost
    assert actual == pytest.approx(rows[0].objective_decrease_per_unit * step * 100.0, rel=0.05)


def test_an_infeasible_start_goes_through_the_feasibility_phase_and_converges(tmp_path: Path) -> None:
    """Lift Lc0 + 1.5 mm leaves x < 0 at the low end of the range: the phase repairs it, the run converges."""
    study = small_study(initial_lengths={"lift": {"L": 1.0071227324212, "Lc0": 0.0865, "Lc": 0.745},
                                         "tilt": {"L": 1.132185817991, "Lc0": 0.085, "Lc": 0.745}})  # fmt: skip
    problem = StudyProblem(study_from_dict(study, "s.yaml"))
    z0 = problem.initial_point(problem.study.initial_lengths)
    assert problem.max_violation(z0) > 1e-3
    z, phase = feasible_start(problem, z0)
    assert phase is not None and problem.max_violation(z) <= 1e-9
    path = write_study(tmp_path, study)
    assert main(["optimize", str(path), "--out", str(tmp_path / "run"), "--no-figures", "--no-video", "--quiet"]) == 0
    result = json.loads((tmp_path / "run" / "result.json").read_text())
    assert result["feasibility"][0]["initial_max_violation"] > 1e-3
    assert result["solver"]["max_violation_scaled"] <= 1e-6


def test_bounds_that_exclude_the_built_crane_start_inside_them_and_converge(tmp_path: Path) -> None:
    """Tilt L >= 1.2 m excludes the built crane (1.132 m): the start moves into the bounds, says so, and converges."""
    study = small_study(bounds={"lift": {"low": [0.8, 0.04, 0.6], "up": [1.25, 0.3, 1.0]},
                                "tilt": {"low": [1.2, 0.04, 0.6], "up": [1.35, 0.3, 1.0]}})  # fmt: skip
    path = write_study(tmp_path, study)
    assert main(["optimize", str(path), "--out", str(tmp_path / "run"), "--no-figures", "--no-video", "--quiet"]) == 0
    result = json.loads((tmp_path / "run" / "result.json").read_text())
    assert result["initial"]["lengths"]["tilt"]["L"] == pytest.approx(1.2)
    assert result["optimal"]["lengths"]["tilt"]["L"] >= 1.2 - 1e-9
    assert result["solver"]["max_violation_scaled"] <= 1e-6
    phase = result["feasibility"][0]  # the step that moved the start into the bounds, and what it changed
    assert phase["start"] == 0 and phase["initial_max_violation"] == pytest.approx(1.2 - 1.132185818, abs=1e-6)
    assert any(line.startswith("tilt.L: 1132.2 -> 1200.0 mm") for line in phase["changes"])
    assert phase["final_max_violation"] <= 1e-9
    summary = (tmp_path / "run" / "summary.md").read_text(encoding="utf-8")  # the answer says from where it counts
    assert "the feasibility phase moved it: tilt.L: 1132.2 -> 1200.0 mm" in summary
    assert "measured from the moved start" in summary


def test_an_impossible_payload_exits_3_naming_the_limit(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A 2 t payload exceeds the lift EMLA at every length: exit 3, the limit named with its excess and time."""
    path = write_study(tmp_path, small_study(payload=2000.0))
    assert main(["optimize", str(path), "--out", str(tmp_path / "run"), "--no-figures", "--no-video", "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "EMLA" in err and "exceeded by" in err and "at t =" in err
    assert not (tmp_path / "run" / "result.json").exists()


def test_each_length_moved_by_the_tolerance_keeps_every_nlp_row(solved: tuple[StudyProblem, np.ndarray]) -> None:
    """Each length moved by +-t (optimal trajectory kept): every nominal fine-grid row holds (bounds: search box)."""
    problem, z = solved
    study = problem.study
    short = dataclasses.replace(study, crane_description=buildable_crane(study.crane, study.build.stroke_margin))
    fine = TaskProblem(
        short,
        id_path="mujoco",
        times=study.grid.fine_times(),
        cost_scale=problem.problems[0].cost_scale,
        tightened=False,
    )
    t = study.build.tolerance
    for k in range(6):
        for sign in (-1.0, 1.0):
            moved = np.array(z)
            moved[k] += sign * t
            margins = fine.margins(moved)
            assert margins.min() >= -1e-6, (k, sign, fine.constraint_names[int(np.argmin(margins))])


def test_mounting_rows_hold_the_pivots_in_their_polygons_for_every_built_design() -> None:
    """Built space shrunk to +-20 mm along the path: the lift pivot stops t from the edge; every corner stays inside."""
    from hiab_sim.crane.loader import load_crane
    from hiab_sim.crane.mounting import built_space, polygon_margins
    from hiab_sim.crane.tolerance import check_tolerance

    space = built_space(load_crane("xs031"), along=0.02, across=0.05)
    mounting = {"lift": [list(v) for v in space.lift or ()], "tilt": [list(v) for v in space.tilt or ()]}
    study = study_from_dict(small_study(mounting=mounting), "m.yaml")
    problem = StudyProblem(study)
    z = solve(problem, study.initial_lengths, progress=None).z
    lengths = problem.unpack(z)[0]
    shift = lengths.as_array() - study.initial_lengths.as_array()
    assert abs(shift[0]) <= 0.02 + 1e-9 and abs(shift[3]) <= 0.02 + 1e-9
    # the lift pivot wants a longer L: it stops the tolerance (|dg/dL| = 1 along the path) and 1 um from the edge
    assert abs(shift[0]) == pytest.approx(0.02 - study.build.tolerance - 1e-6, abs=1e-8)
    check = check_tolerance(lambda x: polygon_margins(space, study.crane, x), lengths, study.build.tolerance)
    assert check.ok, check.summary()
    block = next(b.block for b in problem.blocks if b.block.name == "mounting")
    ev = problem.evaluate(z).tasks[0]
    jac = block.jacobian(ev, None).dxi  # type: ignore[arg-type, union-attr]
    np.testing.assert_allclose(jac, _xi_central_differences(block, ev), atol=1e-5)


def test_tracking_band_multipliers_predict_a_wider_band(solved: tuple[StudyProblem, np.ndarray]) -> None:
    """The position-band multipliers predict the re-solved cost change of a 0.01 mm wider band within 5 %."""
    problem, z = solved
    study = problem.study
    sens = sensitivity(problem, z)
    predicted = sum(
        m.objective_decrease_per_unit for m in sens.multipliers if m.constraint.startswith("tracking.position.")
    )
    assert predicted > 0.0
    delta = 1e-5  # m
    wider = dataclasses.replace(
        study, tracking=dataclasses.replace(study.tracking, position=study.tracking.position + delta)
    )
    p2 = StudyProblem(wider, cost_scales=[problem.problems[0].cost_scale])
    z2 = solve(p2, study.initial_lengths, progress=None, z0=z).z
    actual = (problem.evaluate(z).cost - p2.evaluate(z2).cost) / (delta * 1e3)  # per mm
    assert actual == pytest.approx(predicted, rel=0.05)


@pytest.mark.e2e
@pytest.mark.parametrize("name", ["xs031_spiral", "xs031_spiral_payload", "seed_scale_spiral"])
def test_shipped_studies_print_a_rounded_design_that_mjcf_accepts(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Each shipped study prints a mm-rounded design; its export command runs; its fine-grid re-check is <= 1e-6."""
    out = tmp_path / name
    assert main(["optimize", f"optimize/{name}.yaml", "--out", str(out), "--no-figures", "--no-video", "--quiet"]) == 0
    printed = capsys.readouterr().out
    marker = "Model of the buildable design: hiab-sim "
    command = next(line.split(marker)[1] for line in printed.splitlines() if marker in line)
    result = json.loads((out / "result.json").read_text())["buildable"]
    xi = np.array([result["lengths"][c][k] for c in ("lift", "tilt") for k in ("L", "Lc0", "Lc")])
    np.testing.assert_allclose(xi * 1e3, np.round(xi * 1e3), atol=1e-9)
    assert (
        result["recheck"]["margin"] <= 1e-6 and result["crane_check"]["passed"] and result["tolerance_check"]["passed"]
    )
    assert main([*command.split(), "-o", str(tmp_path / "crane.xml")]) == 0


@pytest.mark.parametrize(
    ("build", "field"),
    [({"tolerance": 0.0}, "build.tolerance"), ({"stroke_margin": -1e-3}, "build.stroke_margin"), ({"tol": 1}, "build")],
)
def test_bad_build_settings_exit_2_naming_the_field(
    build: dict[str, float], field: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A tolerance <= 0, a negative stroke margin or an unknown key: exit 2, the field named, nothing written."""
    path = write_study(tmp_path, small_study(build=build))
    assert main(["optimize", str(path), "--out", str(tmp_path / "run"), "--no-figures", "--no-video", "--quiet"]) == 2
    assert field in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


def test_mjcf_stroke_margin_shortens_the_range_the_lengths_must_serve(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The default optimum rounded to 1 mm fails the full tilt range but passes with --stroke-margin 0.004."""
    lengths = "1.25,0.3,0.735,1.24,0.3,0.637"
    assert main(["mjcf", "--lengths", lengths, "-o", str(tmp_path / "a.xml")]) == 2
    assert "tilt.joint_range" in capsys.readouterr().err
    assert main(["mjcf", "--stroke-margin", "0.004", "--lengths", lengths, "-o", str(tmp_path / "b.xml")]) == 0
    assert main(["mjcf", "--stroke-margin", "-0.001", "-o", str(tmp_path / "c.xml")]) == 2
    assert "--stroke-margin" in capsys.readouterr().err


def test_result_sections_round_trip_typed(tmp_path: Path) -> None:
    """buildable, feasibility and sensitivity load back as typed sections from result.json."""
    from hiab_sim.results.read import read_result

    study = small_study(initial_lengths={"lift": {"L": 1.0071227324212, "Lc0": 0.0865, "Lc": 0.745},
                                         "tilt": {"L": 1.132185817991, "Lc0": 0.085, "Lc": 0.745}})  # fmt: skip
    path = write_study(tmp_path, study)
    assert main(["optimize", str(path), "--out", str(tmp_path / "run"), "--no-figures", "--no-video", "--quiet"]) == 0
    r = read_result(tmp_path / "run")
    assert r.buildable is not None and r.buildable.recheck.passed and r.buildable.tolerance_check.passed
    assert r.feasibility is not None and r.feasibility[0].changes and r.feasibility[0].final_max_violation <= 1e-9
    assert r.sensitivity is not None and all(m.multiplier > 0.0 for m in r.sensitivity.multipliers)
    assert r.sensitivity.kkt_residual < 1e-3

"""Energy map: the stacked-design analytic path, the map against the optimiser, mixes and machine files.

Independent paths: a duty mix's cell against each task's own one-task study, a machine file's map of
the XS 031 against the crane file's, the map's stroke rows against the crane's stacked analytic ID.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lengths_helper import CRANE, feasible_lengths
from test_study_small import TINY, machine_form, small_study, write_study

from hiab_sim.cli import main
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.dynamics.analytic_id import analytic_inverse_dynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import STROKE_SCALE
from hiab_sim.study.run import run_study
from hiab_sim.study.spec.study_file import load_study, study_from_dict
from hiab_sim.sweep.energy_map import energy_map, evaluate_designs, optimum_design, start_design

UNIT = st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6)
#: The crane file's bounds of the tiny study; the machine file's form of it takes the machine's own.
CRANE_BOUNDS = small_study()["bounds"]


def two_task_mix(objective: str = "costf2") -> dict[str, Any]:
    """The tiny study as a mix of two tasks: its spiral (weight 1) and a smaller spiral with a payload (weight 3)."""
    data = small_study(**TINY)
    spiral = {"kind": "spiral", **data.pop("reference")}
    second = {**spiral, "centre_joints": [0.7, -1.4], "end_radius": 0.1}
    data["tasks"] = [
        {"name": "spiral", "weight": 1.0, "reference": spiral},
        {"name": "second", "weight": 3.0, "reference": second, "payload": 80.0},
    ]
    data["objective"] = objective
    return data


def one_task(mix: dict[str, Any], k: int) -> dict[str, Any]:
    """Task k of a mix as a study of its own (weight 1)."""
    return {**mix, "tasks": [{**mix["tasks"][k], "weight": 1.0}]}


@settings(max_examples=15, deadline=None)
@given(designs=st.lists(UNIT, min_size=1, max_size=4), seed=st.integers(0, 1000))
def test_stacked_designs_match_the_per_design_path(designs: list[list[float]], seed: int) -> None:
    """Forces, rates and strokes of D stacked designs equal D calls of the per-design analytic path."""
    rng = np.random.default_rng(seed)
    T = 12
    q = np.column_stack([rng.uniform(0.4, 0.8, T), rng.uniform(-1.5, -1.1, T), rng.uniform(0.2, 0.6, T)])
    dq, ddq = rng.normal(0.0, 0.2, (T, 3)), rng.normal(0.0, 0.5, (T, 3))
    tcp = np.array([30.0, -1500.0, 0.0])
    lengths = [feasible_lengths(np.array(u)) for u in designs]
    stacked = batched_inverse_dynamics(CRANE, np.array([x.as_array() for x in lengths]), q, dq, ddq, tcp)
    for d, x in enumerate(lengths):
        one = analytic_inverse_dynamics(CRANE, x, JointSamples(q, dq, ddq), tcp_force=tcp)
        for got, want in zip(stacked, (one.force, one.velocity, one.acceleration, one.stroke), strict=True):
            np.testing.assert_allclose(got[d], want, rtol=1e-12, atol=1e-9)


@pytest.fixture(scope="module")
def optimum(tmp_path_factory: pytest.TempPathFactory) -> tuple[StudyProblem, Path, Any]:
    """The tiny study optimised on the analytic path: its problem, result folder and result."""
    folder = tmp_path_factory.mktemp("map")
    study = load_study(write_study(folder, small_study(**TINY)))
    output = run_study(study, folder / "run", progress=None, figures=False)
    return StudyProblem(study, id_path="analytic"), output.folder, output.result


def test_map_at_the_optimum_equals_the_optimisers_objective(optimum: tuple[StudyProblem, Path, Any]) -> None:
    """At the optimum's design on its trajectory the map's costf2, energies and objective are the run's own."""
    problem, folder, result = optimum
    base = optimum_design(folder, problem)
    at = evaluate_designs(problem, base, base.xi[None])
    assert at.costf2[0] == pytest.approx(result.optimal.collocation_cost_W2s, rel=1e-10)
    assert at.net_energy[0] == pytest.approx(result.optimal.net_electrical_energy_J, rel=1e-10)
    assert at.objective[0] == pytest.approx(result.history[-1].scaled_cost, rel=1e-10)
    assert at.battery_energy[0] == pytest.approx(result.energy.optimal.battery_energy_J, rel=1e-10)
    assert at.feasible[0]


def test_map_of_a_battery_energy_study_is_its_objective(tmp_path: Path) -> None:
    """With ``objective: battery_energy`` the map's objective at the optimum is the optimiser's, in joules."""
    study = load_study(write_study(tmp_path, {**small_study(**TINY), "objective": "battery_energy"}))
    output = run_study(study, tmp_path / "run", progress=None, figures=False)
    problem = StudyProblem(study, id_path="analytic")
    base = optimum_design(output.folder, problem)
    m = energy_map(problem, base, (0, 1), 2)
    assert (m.objective, m.objective_unit) == ("battery_energy", "J")
    assert m.at_base.objective[0] == pytest.approx(output.result.history[-1].scaled_cost, rel=1e-9)
    assert m.at_base.battery_energy[0] == pytest.approx(output.result.energy.optimal.battery_energy_J, rel=1e-10)


@pytest.mark.parametrize("variables", [(0, 1), (1, 2), (0, 2)])
def test_no_feasible_cell_beats_the_optimum(
    optimum: tuple[StudyProblem, Path, Any], variables: tuple[int, int]
) -> None:
    """The map's best feasible cell is no better than the optimum, and the cell nearest it is within a grid step.

    The optimum's trajectory is fixed and two lengths vary: the optimum is a KKT point of this slice too,
    so a feasible cell may undercut it only by the optimiser's tolerances (ftol 1e-9 on the scaled cost).
    """
    problem, folder, _ = optimum
    base = optimum_design(folder, problem)
    m = energy_map(problem, base, variables, 12)
    f_opt = m.at_base.objective[0]
    feasible = m.values.feasible
    assert feasible.any()
    assert m.values.objective[feasible].min() >= f_opt - 1e-6
    i, j = variables
    near = np.argmin(np.abs(m.axes[0] - base.xi[i])), np.argmin(np.abs(m.axes[1] - base.xi[j]))
    grid = m.grid(m.values.objective)
    # cells the inverse dynamics refuses are NaN: the step between neighbours along the axes or the diagonals
    diffs = [np.diff(grid, axis=0), np.diff(grid, axis=1), grid[1:, 1:] - grid[:-1, :-1], grid[1:, :-1] - grid[:-1, 1:]]
    step = max(float(np.max(np.abs(d[np.isfinite(d)]))) for d in diffs if np.isfinite(d).any())
    assert abs(grid[near] - f_opt) <= 2.0 * step


def test_stroke_margins_equal_the_cranes_stacked_strokes() -> None:
    """The map's stroke rows are min over the collocation samples of (x, Lc - x, stroke - x) / scale.

    The strokes x come from the crane's stacked analytic ID (``analytic_batch``), not from the NLP.
    """
    study = study_from_dict(small_study(**TINY), "tiny.yaml")
    problem = StudyProblem(study, id_path="analytic")
    base = start_design(problem)
    rng = np.random.default_rng(4)
    xi = base.xi[None] * (1.0 + rng.uniform(-0.002, 0.002, (6, 6)))
    values = evaluate_designs(problem, base, xi)
    # a design whose stroke cannot cover the joint range the ID checks is refused; it fails a row of Xi alone
    refused = ~np.isfinite(values.objective)
    assert all(values.names[b].startswith("working_range.") for b in values.binding[refused])
    xi, values = xi[~refused], replace(values, margins=values.margins[~refused])
    assert len(xi) >= 2
    p = problem.problems[0]
    joints = p.joints(base.coefficients[0])
    _, _, _, x = batched_inverse_dynamics(
        study.crane, xi, joints.position, joints.velocity, joints.acceleration, p.tcp_force
    )
    for j, chain in enumerate(study.crane.chains):
        name = chain.name
        lc = xi[:, 3 * j + 2][:, None]
        want = {
            f"stroke.{name}.x >= 0": x[..., j],
            f"stroke.{name}.x <= Lc": lc - x[..., j],
            f"stroke.{name}.x <= stroke": chain.stroke - x[..., j],
        }
        for row, margin in want.items():
            got = values.margins[:, values.names.index(row)]
            np.testing.assert_allclose(got, margin.min(axis=1) / STROKE_SCALE, rtol=1e-10, atol=1e-10)


def test_mix_cell_is_the_weighted_sum_of_its_tasks_alone() -> None:
    """A cell of a two-task mix: objective, costf2 and energies are sum_k w_k of each task's one-task study.

    Each task alone is its own study (weight 1), its own NLP and start; the battery energy is the objective.
    """
    mix = two_task_mix("battery_energy")
    problem = StudyProblem(study_from_dict(mix, "mix.yaml"), id_path="analytic")
    base = start_design(problem)
    xi = np.vstack([base.xi, base.xi * (1.0 + np.array([0.004, -0.01, 0.003, -0.002, 0.01, -0.004]))])
    values = evaluate_designs(problem, base, xi)
    assert np.isfinite(values.objective).all()
    want = {"objective_value": 0.0, "costf2": 0.0, "net_energy": 0.0, "battery_energy": 0.0}
    for k, task in enumerate(mix["tasks"]):
        alone = StudyProblem(study_from_dict(one_task(mix, k), f"alone{k}.yaml"), id_path="analytic")
        v = evaluate_designs(alone, start_design(alone), xi)
        for key in want:
            want[key] = want[key] + task["weight"] * getattr(v, key)
        # every limit of the task alone is the mix's "<task>: <limit>" (a row of Xi alone is held once)
        matched = 0
        for r, name in enumerate(v.names[:-1]):
            column = f"{task['name']}: {name}"
            if column in values.names:
                np.testing.assert_allclose(values.margins[:, values.names.index(column)], v.margins[:, r], atol=1e-12)
                matched += 1
        assert matched >= 15
    for key, expected in want.items():
        np.testing.assert_allclose(getattr(values, key), expected, rtol=1e-12)
    np.testing.assert_allclose(values.objective, values.objective_value / abs(want["objective_value"][0]), rtol=1e-9)


def test_machine_file_map_of_the_xs031_equals_the_crane_files(tmp_path: Path) -> None:
    """The XS 031 through its machine file (tracking xt2) maps the same numbers as through its crane file."""
    crane = small_study(**TINY)
    machine = machine_form(crane)
    maps = {}
    for key, data in (("crane", crane), ("machine", machine)):
        problem = StudyProblem(load_study(write_study(tmp_path, data, f"{key}.yaml")), id_path="analytic")
        base = start_design(problem)
        assert problem.model.design_names[:2] == ("lift.L", "lift.Lc0")
        xi = np.vstack([base.xi, base.xi * (1.0 + np.array([0.01, 0.02, 0.0, 0.0, -0.01, 0.0]))])
        maps[key] = evaluate_designs(problem, base, xi)
    a, b = maps["crane"], maps["machine"]
    np.testing.assert_array_equal(a.xi, b.xi)
    assert np.isfinite(a.objective).all() and a.feasible[0]
    for key in ("objective_value", "objective", "costf2", "net_energy", "drawn_energy", "battery_energy"):
        np.testing.assert_allclose(getattr(b, key), getattr(a, key), rtol=1e-9)
    shared = [n for n in b.names if n in a.names and not n.startswith("domain")]
    assert len(shared) >= 20
    for name in shared:
        np.testing.assert_allclose(b.margins[:, b.names.index(name)], a.margins[:, a.names.index(name)], atol=1e-8)


def test_energy_map_cli_writes_the_map_and_names_the_base(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The CLI writes JSON, NPZ and PNG, says which base design, that the trajectory is fixed, and the objective."""
    study = write_study(tmp_path, small_study(**TINY))
    assert main(["energy-map", str(study), "--grid", "4", "--out", str(tmp_path / "map")]) == 0
    out = capsys.readouterr().out
    assert "start of the study" in out and "trajectory" in out and "fixed" in out
    summary = json.loads((tmp_path / "map" / "energy_map.json").read_text())
    assert summary["variables"] == ["lift.L", "lift.Lc0"] and summary["cells"] == 16
    assert (summary["objective_name"], summary["objective_unit"]) == ("costf2", "W^2 s")
    assert (tmp_path / "map" / "energy_map.png").stat().st_size > 10_000
    assert np.load(tmp_path / "map" / "energy_map.npz")["objective"].shape == (4, 4)


@pytest.mark.e2e
def test_energy_map_cli_maps_a_duty_mix(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A duty mix is mapped (not refused): its tasks and weights, the objective's unit and per-task limits."""
    study = write_study(tmp_path, two_task_mix("battery_energy"))
    assert (
        main(["energy-map", str(study), "--vars", "lift.L,tilt.Lc0", "--grid", "3", "--out", str(tmp_path / "m")]) == 0
    )
    out = capsys.readouterr().out
    assert "battery_energy weighted over the tasks (1 x spiral + 3 x second) [J" in out
    summary = json.loads((tmp_path / "m" / "energy_map.json").read_text())
    assert summary["tasks"] == [{"name": "spiral", "weight": 1.0}, {"name": "second", "weight": 3.0}]
    assert summary["variables"] == ["lift.L", "tilt.Lc0"] and summary["objective_unit"] == "J"
    assert summary["at_base"]["binding_constraint"].split(": ")[0] in ("spiral", "second")


@pytest.mark.parametrize("bad", ["lift.L", "lift.L,lift.L", "lift.L,boom.X"])
def test_bad_vars_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], bad: str) -> None:
    """--vars must name two distinct decision variables; otherwise one line naming --vars and the allowed names."""
    assert main(["energy-map", "--vars", bad, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "--vars" in err and "lift.L, lift.Lc0, lift.Lc, tilt.L, tilt.Lc0, tilt.Lc" in err
    assert not any(tmp_path.iterdir())


@pytest.mark.e2e
def test_map_at_a_mix_optimum_reads_every_tasks_trajectory(tmp_path: Path) -> None:
    """At a two-task mix's optimum (its result folder) the map gives the run's weighted costf2, energies, objective.

    The base reads each task's trajectory (``task<k>_`` arrays) and fits its spline; about 45 s on 2 shared cores.
    """
    study = load_study(write_study(tmp_path, two_task_mix("battery_energy")))
    output = run_study(study, tmp_path / "run", progress=None, figures=False)
    problem = StudyProblem(study, id_path="analytic")
    at = evaluate_designs(problem, optimum_design(output.folder, problem), output.result.optimal.lengths.as_array())
    result = output.result
    assert at.objective[0] == pytest.approx(result.history[-1].scaled_cost, rel=1e-9)
    assert at.costf2[0] == pytest.approx(result.optimal.collocation_cost_W2s, rel=1e-9)
    assert at.net_energy[0] == pytest.approx(result.optimal.net_electrical_energy_J, rel=1e-9)
    assert at.battery_energy[0] == pytest.approx(result.energy.optimal.battery_energy_J, rel=1e-9)
    assert at.feasible[0]


def test_design_space_modules_hold_no_machine_names_as_literals() -> None:
    """No string constant of the sweep package or its three commands equals a name a shipped machine file gives."""
    import ast

    from test_machine_names import PACKAGE, shipped_names

    names = shipped_names()
    modules = [
        *sorted((PACKAGE / "sweep").glob("*.py")),
        *(PACKAGE / "cli" / f for f in ("energy_map.py", "pareto.py", "sweep.py")),
    ]
    found = [
        f"{path.relative_to(PACKAGE)}:{node.lineno}: {node.value!r}"
        for path in modules
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in names
    ]
    assert not found, found

"""Structural NLP rows: exact-gradient buckling, pin-load and natural-frequency rows change the optimum when binding."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import hiab_sim
from hiab_sim.crane.description import LinkLengths
from hiab_sim.errors import InvalidInputError
from hiab_sim.structure.buckling import buckling_samples
from hiab_sim.structure.natural_frequency import natural_frequencies
from hiab_sim.study.analysis.sensitivity import sensitivity
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.solvers.slsqp import solve
from hiab_sim.study.spec.study_file import Study, study_from_dict

sys.path.insert(0, str(Path(__file__).parent))
from test_study_small import small_study

PAYLOAD_KG = 300.0
EMLA_PRESET = Path(hiab_sim.__file__).parent / "presets" / "emla_xs031.yaml"


def _study(folder: Path, **overrides: Any) -> Study:
    return study_from_dict(small_study(payload=PAYLOAD_KG, **overrides), folder / "study.yaml")


def _weak_screws(folder: Path, root_diameter: float) -> str:
    """An EMLA file whose lift and tilt screws have a thinner root: the free optimum would buckle them."""
    data = yaml.safe_load(EMLA_PRESET.read_text())
    data["screw"]["root_diameter"] = {"value": root_diameter, "source": "model: a thin screw for a test"}
    path = folder / "weak_emla.yaml"
    path.write_text(yaml.safe_dump(data))
    return path.name


def _worst_utilisation(study_problem: StudyProblem, z: np.ndarray) -> float:
    problem = study_problem.problems[0]
    ev = problem.evaluate(z)
    b = buckling_samples(problem.crane, problem.emlas, ev.lengths, ev.joints.position, ev.actuators.force)
    return float(np.max(b.utilisation))


def test_buckling_row_changes_the_optimum_of_a_study_whose_screws_would_buckle(tmp_path: Path) -> None:
    """Thin screws: the free optimum pushes past P_cr / 2; with the row the optimum moves and the row binds."""
    emla = _weak_screws(tmp_path, 0.0415)
    free = _study(tmp_path, emla=emla)
    p_free = StudyProblem(free)
    z_free = solve(p_free, free.initial_lengths, progress=None).z
    assert _worst_utilisation(p_free, p_free.initial_point(free.initial_lengths)) < 1.0
    assert _worst_utilisation(p_free, z_free) > 1.02

    held = _study(tmp_path, emla=emla, structure={"buckling": True})
    p_held = StudyProblem(held)
    z_held = solve(p_held, held.initial_lengths, progress=None).z
    assert p_held.max_violation(z_held) < 1e-6
    assert _worst_utilisation(p_held, z_held) <= 1.0 + 1e-6
    held_task = p_held.problems[0]
    rows = held_task.evaluate(z_held).constraints[held_task.layout.slices["structure.buckling"]]
    assert np.min(rows) < 1e-4  # active
    moved = np.abs(p_held.unpack(z_held)[0].as_array() - p_free.unpack(z_free)[0].as_array())
    assert np.max(moved) > 5e-3
    assert held_task.evaluate(z_held).cost > p_free.problems[0].evaluate(z_free).cost


@pytest.mark.e2e
def test_min_natural_frequency_above_the_free_optimum_moves_it_and_is_active(tmp_path: Path) -> None:
    """A floor 0.2 % above the free optimum's lowest frequency moves it, binds, and shows in the sensitivities."""
    free = _study(tmp_path)
    p_free = StudyProblem(free)
    z_free = solve(p_free, free.initial_lengths, progress=None).z
    free_task = p_free.problems[0]
    ev = free_task.evaluate(z_free)
    modes = natural_frequencies(
        free_task.crane, free_task.emlas, ev.lengths, ev.joints.position, free_task.tcp_force, payload_kg=PAYLOAD_KG
    )
    f_free = float(np.min(modes.lowest_Hz))
    floor = 1.002 * f_free
    # a feasible start above the floor: the free optimum with a longer lift rod (stiffer: shorter strokes)
    start = ev.lengths.as_array()
    start[2] += 0.015
    study = _study(tmp_path, structure={"min_natural_frequency_Hz": floor})
    problem = StudyProblem(study)
    result = solve(problem, LinkLengths.from_array(start), progress=None)
    assert problem.max_violation(result.z) < 1e-6
    task = problem.problems[0]
    rows = task.evaluate(result.z).constraints[task.layout.slices["structure.natural_frequency"]]
    assert np.min(rows) < 1e-4 and np.min(rows) > -1e-6
    moved = np.abs(problem.unpack(result.z)[0].as_array() - ev.lengths.as_array())
    assert np.max(moved) > 1e-3
    names = [m.constraint for m in sensitivity(problem, result.z).multipliers]
    assert any(name.startswith("structure.natural_frequency") for name in names)


def test_structure_rows_jacobian_matches_differences_of_the_problem(tmp_path: Path) -> None:
    """Every structural row's Jacobian w.r.t. z agrees with central differences of the problem's rows."""
    study = _study(
        tmp_path,
        structure={
            "buckling": True,
            "pin_load_limits": {"lift.base_pivot": 2.0e5, "tilt.rod_end": 2.0e5},
            "min_natural_frequency_Hz": 1.0,
        },
    )
    problem = TaskProblem(study, task=study.tasks[0])
    z = problem.initial_point(study.initial_lengths)
    rng = np.random.default_rng(2)
    z = z + 1e-3 * rng.normal(size=z.size) * (np.arange(z.size) >= 6)
    jac = problem.constraints_jacobian(z)
    jac = jac.toarray() if hasattr(jac, "toarray") else np.asarray(jac)
    h = 1e-6
    steps = h * np.eye(z.size)
    fd_all = np.stack([(problem.constraints(z + e) - problem.constraints(z - e)) / (2 * h) for e in steps], axis=1)
    for block in ("structure.buckling", "structure.pin_load", "structure.natural_frequency"):
        rows = problem.layout.slices[block]
        fd = fd_all[rows]
        scale = max(1.0, float(np.max(np.abs(fd))))
        assert np.max(np.abs(jac[rows] - fd)) < 2e-4 * scale, block


def test_unknown_pin_or_bad_frequency_is_rejected(tmp_path: Path) -> None:
    """A pin the crane does not have, or a non-positive frequency floor, names the field."""
    with pytest.raises(InvalidInputError, match="pin_load_limits"):
        _study(tmp_path, structure={"pin_load_limits": {"lift.elbow": 1e5}})
    with pytest.raises(InvalidInputError, match="min_natural_frequency_Hz"):
        _study(tmp_path, structure={"min_natural_frequency_Hz": -3.0})

"""A small, fast study shared by the optimiser tests (few control points, coarse grid, analytic ID)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml


def small_study(**overrides: Any) -> dict[str, Any]:
    """Study mapping: XS 031, 16 control points, 13 collocation points, a 0.05 -> 0.25 m spiral."""
    study: dict[str, Any] = {
        "name": "small",
        "crane": "xs031",
        "spline": {"control_points": 16, "degree": 5},
        "grid": {"duration": 6.25, "intervals": 12, "fine_factor": 10},
        "reference": {
            "centre_joints": [0.6, -1.3],
            "start_radius": 0.05,
            "end_radius": 0.25,
            "turns": 1.0,
            "telescope_start": 0.4,
            "telescope_amplitude": 0.2,
        },
        "tracking": {"position": 2e-3, "velocity": 1e-2, "acceleration": 0.1, "collocation_fraction": 0.5},
        "bounds": {
            "lift": {"low": [0.8, 0.04, 0.6], "up": [1.25, 0.3, 1.0]},
            "tilt": {"low": [0.9, 0.04, 0.6], "up": [1.35, 0.3, 1.0]},
        },
        "solver": {"maxiter": 100, "ftol": 1e-9, "id_path": "analytic"},
    }
    for key, value in overrides.items():
        study[key] = value
    return study


#: A smaller spiral on a coarse grid: each point optimises in a few seconds.
TINY = {
    "spline": small_study()["spline"],
    "grid": {**small_study()["grid"], "intervals": 8, "fine_factor": 4},
    "reference": {**small_study()["reference"], "end_radius": 0.15, "telescope_amplitude": 0.1},
}


def write_study(folder: Path, study: dict[str, Any], name: str = "study.yaml") -> Path:
    """Write a study mapping as YAML; return its path."""
    path = folder / name
    path.write_text(yaml.safe_dump(study))
    return path


def test_small_study_loads_with_a_feasible_start() -> None:
    """The shared small study is valid and its start satisfies every constraint."""
    from hiab_sim.study.nlp.task_problem import TaskProblem
    from hiab_sim.study.spec.study_file import study_from_dict

    study = study_from_dict(small_study(), "small.yaml")
    problem = TaskProblem(study)
    assert problem.max_violation(problem.initial_point(study.initial_lengths)) <= 1e-9


def machine_form(crane: dict[str, Any]) -> dict[str, Any]:
    """A crane file's study mapping of the XS 031 as the same study of its machine file (tracking xt2).

    The crane file's study keeps the crane's full joint range, the machine file's the machine's (the
    same range); the machine file declares the decision variables' bounds.
    """
    machine = {k: v for k, v in crane.items() if k not in ("crane", "bounds")}
    return machine | {
        "machine": "xs031",
        "emla": "default",
        "tracked": ["xt2"],
        "bounds": {"joint_velocity": [0.6, 0.6, 0.5], "working_range": "machine"},
    }

"""The structure section of a result: built from a design's motion, written and read back, tabled and drawn."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.results.codec import from_json, to_json
from hiab_sim.structure.pin_paths import pin_loads
from hiab_sim.structure.report import structure_table
from hiab_sim.structure.summary import StructureSummary, design_structure
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.spec.study_file import study_from_dict

sys.path.insert(0, str(Path(__file__).parent))
from test_study_small import small_study


def test_structure_section_matches_the_mujoco_pin_loads_and_round_trips(tmp_path: Path) -> None:
    """Peaks of the summary equal MuJoCo's pin forces on the same motion; JSON round trip; the table lists every pin."""
    study = study_from_dict(small_study(payload=200.0), tmp_path / "study.yaml")
    problem = TaskProblem(study, tightened=False, task=study.tasks[0])
    ev = problem.evaluate(problem.initial_point(study.initial_lengths))
    joints = JointSamples(ev.joints.position, ev.joints.velocity, ev.joints.acceleration)
    design = design_structure(problem.crane, problem.emlas, ev.lengths, joints, ev.actuators.force, problem.tcp_force)
    mujoco = pin_loads(problem.crane, ev.lengths, joints, "mujoco", tcp_force=problem.tcp_force)
    for name, peak in mujoco.peak().items():
        assert abs(design.pins[name].peak_N - peak) < 1e-9 * peak
    assert design.lowest_frequency_trajectory_Hz is not None and design.lowest_frequency_trajectory_Hz > 1.0
    assert design.lowest_frequency_working_range_Hz is not None
    summary = StructureSummary(initial=design, optimal=design)
    assert from_json(StructureSummary, to_json(summary)) == summary
    table = structure_table(summary, velocity_bandwidth_Hz=2.0)
    assert all(f"pin {name}" in table for name in design.pins)
    assert "velocity loop 2 Hz" in table


def test_optimised_result_reports_structure_and_the_figure_draws_it(tmp_path: Path) -> None:
    """An optimisation writes the structure section for both designs; it reads back; the figure is written."""
    from hiab_sim.api import optimize
    from hiab_sim.results.read import read_result
    from hiab_sim.structure.report import natural_frequency_figure

    study = study_from_dict(small_study(payload=200.0), tmp_path / "study.yaml")
    result = optimize(study, tmp_path / "run", figures=False, progress=None)
    assert result.structure is not None
    assert set(result.structure.optimal.buckling) == {p.name for p in study.emlas if p.screw is not None}
    assert read_result(tmp_path / "run").structure == result.structure
    arrays = dict(np.load(tmp_path / "run" / "trajectory.npz"))
    png = natural_frequency_figure(study.crane, study.emlas, result, arrays, tmp_path / "structure.png")
    assert png.stat().st_size > 10_000

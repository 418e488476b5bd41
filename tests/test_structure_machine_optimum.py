"""A buckling row moves the excavator's optimum when a slender bucket screw would buckle at the free optimum.

The small excavator move of ``machine_result_helper`` (4 s, 50 kg) with the arm's hinge distance
and the bucket's retracted length held near the file's values (so that the free optimum moves the
bucket linkage's base pin G instead: the bucket's column grows from 1.111 to 1.130 m and its push by
3 %) and a 15.8 mm bucket screw (the others the file's 43.5 mm): the start holds n f / P_cr = 0.98,
the free optimum would reach 1.05.
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import hiab_sim
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.structure.machine_structure import machine_buckling
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.solvers.slsqp import solve
from hiab_sim.study.spec.study_file import Study, load_study

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine_result_helper import EXCAVATOR_STUDY, excavator_move

PRESETS = Path(hiab_sim.__file__).parent / "presets"
#: The slender bucket screw's root diameter [m] (model: chosen so that only the bucket's row can bind).
BUCKET_ROOT_DIAMETER_M = 0.0158
#: (file text, held bounds) of the variables held near the file's values (|AE| = 1.30173 m, x0 = 0.834 m).
HELD = {
    "L: {kind: hinge_distance, pivot: base, bounds: [1.11, 1.50]}": "L: {kind: hinge_distance, pivot: base, "
    "bounds: [1.30, 1.31]}",
    "x0: {kind: retracted_length, bounds: [0.734, 0.934]}": "x0: {kind: retracted_length, bounds: [0.83, 0.84]}",
}


def _study(folder: Path, rows: bool) -> Study:
    """The excavator move with the held variables, the slender bucket screw and, with ``rows``, a buckling row."""
    excavator_move(folder)
    text = (PRESETS / "exact_excavator.yaml").read_text()
    for old, new in HELD.items():
        assert old in text
        text = text.replace(old, new)
    (folder / "machine.yaml").write_text(text)
    emla = yaml.safe_load((PRESETS / "emla_exact.yaml").read_text())
    screw = copy.deepcopy(emla["screw"])
    screw["root_diameter"] = {"value": BUCKET_ROOT_DIAMETER_M, "source": "model: a slender screw for a test"}
    emla["actuators"]["bucket"]["screw"] = screw
    (folder / "emla.yaml").write_text(yaml.safe_dump(emla))
    data = {**copy.deepcopy(EXCAVATOR_STUDY), "machine": "machine.yaml", "emla": "emla.yaml"}
    if rows:
        data["structure"] = {"buckling": True}
    (folder / "study.yaml").write_text(yaml.safe_dump(data))
    return load_study(folder / "study.yaml")


def _bucket_utilisation(problem: StudyProblem, z: np.ndarray) -> float:
    """The bucket screw's largest n f / P_cr on the collocation grid, forces from the MuJoCo path."""
    task = problem.problems[0]
    ev = task.evaluate(z)
    machine = task.model.machine_at(ev.lengths)
    j = ev.joints
    force = None if task.tcp_force is None else np.asarray(task.tcp_force)[..., :2]
    out = make_machine_dynamics(machine, None, "mujoco")(j.position, j.velocity, j.acceleration, tcp_force=force)
    b = machine_buckling(machine, task.emlas, tuple(out.names), np.asarray(out.stroke), np.asarray(out.force))
    return float(np.max(b.utilisation[:, b.names.index("bucket")]))


@pytest.mark.e2e
def test_buckling_row_moves_the_excavator_optimum_of_a_slender_bucket_screw(tmp_path: Path) -> None:
    """Free: the bucket screw would buckle; held: the row binds at 1, the pin G moves and the energy rises."""
    (tmp_path / "free").mkdir()
    (tmp_path / "held").mkdir()
    free = StudyProblem(_study(tmp_path / "free", rows=False))
    z_free = solve(free, free.study.initial_lengths, progress=None).z
    assert _bucket_utilisation(free, free.initial_point(free.study.initial_lengths)) < 1.0
    assert _bucket_utilisation(free, z_free) > 1.03
    held = StudyProblem(_study(tmp_path / "held", rows=True))
    z_held = solve(held, held.study.initial_lengths, progress=None).z
    assert held.max_violation(z_held) < 1e-6
    assert _bucket_utilisation(held, z_held) == pytest.approx(1.0, abs=1e-5)  # the MuJoCo path: the row binds
    names = held.model.design_names
    moved = held.unpack(z_held)[0].as_array() - free.unpack(z_free)[0].as_array()
    assert np.abs(moved[names.index("bucket.Gy")]) > 0.02  # m
    assert held.problems[0].evaluate(z_held).cost > free.problems[0].evaluate(z_free).cost

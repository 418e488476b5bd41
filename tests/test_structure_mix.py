"""A duty mix's structure section: every task's own section, their envelope, the rows held on every task.

The two-task mix of ``test_mix`` on a coarse grid, 300 kg on its second task and thin screws (the
free mix optimum would push the lift screw to n f / P_cr = 1.14 on that task), with a buckling row.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from hiab_sim.design_report.analysis import structure
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.results.read import read_result
from hiab_sim.structure.buckling import buckling_samples
from hiab_sim.structure.natural_frequency import natural_frequencies
from hiab_sim.structure.pin_paths import pin_loads
from hiab_sim.structure.report import structure_table, task_structure_table
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.run import run_study
from hiab_sim.study.spec.study_file import Study, study_from_dict

sys.path.insert(0, str(Path(__file__).parent))
from test_mix import two_tasks
from test_structure_nlp import _weak_screws
from test_study_small import TINY

#: Payload of the second task [kg] and the thin screws' root diameter [m] (test_structure_nlp's).
PAYLOAD_KG = 300.0
ROOT_DIAMETER_M = 0.0415


def _study(folder: Path) -> Study:
    data = two_tasks()
    data["grid"] = TINY["grid"]
    data["tasks"][1]["payload"] = PAYLOAD_KG
    data["emla"] = _weak_screws(folder, ROOT_DIAMETER_M)
    data["structure"] = {"buckling": True}
    return study_from_dict(data, folder / "two.yaml")


@pytest.fixture(scope="module")
def mix_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Study, Path]:
    folder = tmp_path_factory.mktemp("structure_mix")
    study = _study(folder)
    run_study(study, folder / "run", progress=None, figures=True, cross=False)
    return study, folder / "run"


def _own(study: Study, run: Path, k: int, design: str) -> tuple[dict[str, float], dict[str, float], float]:
    """Task k's pin peaks (MuJoCo path) [N], screw utilisations [-], lowest frequency on its motion [Hz].

    From the result folder's trajectory alone: the task's fine-grid motion and actuator forces.
    """
    arrays = dict(np.load(run / "trajectory.npz"))
    p = StudyProblem(study).problems[k]
    task = study.tasks[k]
    key = f"task{k}_{design}_"
    joints = JointSamples(arrays[key + "position"], arrays[key + "velocity"], arrays[key + "acceleration"])
    tcp_force = task.id_force(p.kin, p.model.gravity, arrays[f"task{k}_time"])
    lengths = crane_lengths(getattr(read_result(run), design).lengths)
    peaks = pin_loads(p.crane, lengths, joints, "mujoco", tcp_force=tcp_force).peak()
    b = buckling_samples(p.crane, p.emlas, lengths, joints.position, arrays[key + "actuator_force"])
    utilisation = {name: float(np.max(b.utilisation[:, j])) for j, name in enumerate(b.names)}
    modes = natural_frequencies(p.crane, p.emlas, lengths, joints.position, tcp_force, payload_kg=task.payload.mass)
    return peaks, utilisation, float(np.min(modes.lowest_Hz))


@pytest.mark.e2e
def test_mix_envelope_is_the_worst_over_each_tasks_own_structure(mix_run: tuple[Study, Path]) -> None:
    """Each task's section equals its motion's own values; the envelope is their worst and names its task."""
    study, run = mix_run
    result = read_result(run)
    assert result.tasks is not None and result.structure is not None
    names = [t.name for t in result.tasks]
    for design in ("initial", "optimal"):
        own = [_own(study, run, k, design) for k in range(len(names))]
        envelope = getattr(result.structure, design)
        assert envelope.envelope is not None and envelope.envelope.tasks == tuple(names)
        for k, task in enumerate(result.tasks):
            assert task.structure is not None
            section = getattr(task.structure, design)
            for pin, peak in own[k][0].items():
                assert section.pins[pin].peak_N == pytest.approx(peak, rel=1e-9)
            for screw, u in own[k][1].items():
                assert section.buckling[screw].max_utilisation == pytest.approx(u, rel=1e-12)
            assert section.lowest_frequency_trajectory_Hz == pytest.approx(own[k][2], rel=1e-12)
        for pin, summary in envelope.pins.items():
            peaks = [o[0][pin] for o in own]
            assert summary.peak_N == pytest.approx(max(peaks), rel=1e-9)
            assert envelope.envelope.pin_peak_task[pin] == names[int(np.argmax(peaks))]
        for screw, summary in envelope.buckling.items():
            values = [o[1][screw] for o in own]
            assert summary.max_utilisation == pytest.approx(max(values), rel=1e-12)
            assert envelope.envelope.buckling_task[screw] == names[int(np.argmax(values))]
        worst = max((max(o[1].values()), names[k]) for k, o in enumerate(own))
        assert envelope.envelope.smallest_buckling_margin == pytest.approx(1.0 - worst[0], rel=1e-12)
        assert envelope.envelope.smallest_buckling_margin_task == worst[1]
        frequencies = [o[2] for o in own]
        assert envelope.lowest_frequency_trajectory_Hz == pytest.approx(min(frequencies), rel=1e-12)
        assert envelope.envelope.lowest_frequency_trajectory_task == names[int(np.argmin(frequencies))]
        assert envelope.pins[envelope.most_loaded_pin].peak_N == max(p.peak_N for p in envelope.pins.values())
    # the tasks load the structure differently: the payload's task sets the lift pins, the spiral the telescope
    optimal = result.structure.optimal.envelope
    assert optimal is not None
    assert optimal.pin_peak_task["lift.base_pivot"] == "second" and optimal.buckling_task["telescope"] == "spiral"
    table = structure_table(result.structure)
    assert "(second)" in table and "smallest buckling margin" in table
    per_task = task_structure_table([(t.name, t.structure) for t in result.tasks if t.structure], result.structure)
    assert per_task.splitlines()[0].endswith("| spiral | second | envelope |")
    for png in ("structure_initial_vs_optimal.png", "structure_natural_frequency.png"):
        assert (run / png).stat().st_size > 10_000
    page = structure(result, run)  # the design report's section
    assert "set by task, optimal" in page and "task (optimal design)" in page
    assert "Smallest buckling margin" in page and all(f"<td>{name}</td>" in page for name in names)


@pytest.mark.e2e
def test_buckling_row_of_a_mix_holds_on_every_task_and_binds_where_the_payload_is(
    mix_run: tuple[Study, Path],
) -> None:
    """One buckling block per task (none shared); both tasks feasible; the payload's task's row is active."""
    study, run = mix_run
    problem = StudyProblem(study)
    held = [(b.task, b.block.name) for b in problem.blocks if b.block.name == "structure.buckling"]
    assert held == [(0, "structure.buckling"), (1, "structure.buckling")]
    result = read_result(run)
    assert result.solver.success and result.tasks is not None
    for task in result.tasks:
        assert task.optimal.collocation_max_violation is not None
        assert task.optimal.collocation_max_violation <= 1e-6
    assert result.sensitivity is not None
    active = [m.constraint for m in result.sensitivity.multipliers if "structure.buckling" in m.constraint]
    assert active and all(name.startswith("second: ") for name in active)
    # on the 4x finer grid, between the collocation points, within 1 % (measured 1.0013)
    u = result.structure.optimal.buckling["lift"].max_utilisation if result.structure else None
    assert u is not None and 0.99 < u < 1.01

"""Structure of a machine file's design: pins, screw buckling and natural frequencies on any machine.

Three independent checks: the XS 031 through its machine file (generic tree, Newton-Euler, loop
closure) gives the crane file's closed-form pins, buckling and frequencies; on the excavator the
Newton-Euler and MuJoCo paths agree and a free-vibration simulation of the spring-mounted MuJoCo
model gives the eigenvalue frequencies; the NLP's structural rows of a machine study have the
gradients of central differences and bind when asked to.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from differences_helper import central_steps
from machine_result_helper import EXCAVATOR_STUDY, joint_csv

from hiab_sim.crane.description import LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla.config import load_emla_set
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.machine.loader import load_machine
from hiab_sim.structure.free_vibration import FreeVibration
from hiab_sim.structure.machine_free_vibration import machine_free_vibration_frequency
from hiab_sim.structure.machine_modes import actuator_jacobian, machine_natural_frequencies, mass_matrix
from hiab_sim.structure.machine_structure import machine_design_structure, machine_pin_loads, machine_pin_names
from hiab_sim.structure.summary import design_structure
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.spec.study_file import load_study

#: The crane file's pin of each machine-file pin of the XS 031 (the same pin, two namings).
XS031_PINS = {
    "theta1": "lift.boom_hinge",
    "lift.base_pin": "lift.base_pivot",
    "lift.end_pin": "lift.rod_end",
    "theta2": "tilt.boom_hinge",
    "tilt.base_pin": "tilt.base_pivot",
    "tilt.end_pin": "tilt.rod_end",
}


def _random_motion(machine: Machine, seed: int, samples: int) -> JointSamples:
    rng = np.random.default_rng(seed)
    ranges = [machine.joint_link(j).joint_range for j in machine.joint_names]
    q = np.stack([rng.uniform(lo + 0.05 * (hi - lo), hi - 0.05 * (hi - lo), samples) for lo, hi in ranges], axis=-1)
    n = q.shape[1]
    return JointSamples(q, rng.uniform(-0.2, 0.2, (samples, n)), rng.uniform(-0.5, 0.5, (samples, n)))


@pytest.fixture(scope="module")
def excavator() -> tuple[Machine, object]:
    machine = load_machine("exact")
    return machine, load_emla_set("exact").renamed(tuple(c.name for c in machine.chains))


def test_xs031_machine_file_structure_equals_the_crane_files_closed_form() -> None:
    """Pins, buckling and the on-path frequency of two independent models of the same crane and motion."""
    crane, machine, emlas = load_crane("xs031"), load_machine("xs031"), load_emla_set("xs031")
    joints = _random_motion(machine, 1, 40)
    xi = machine.design_values()
    weight = np.array([0.0, -500.0 * 9.81, 0.0])
    lengths = LinkLengths.from_array(xi)
    force = batched_inverse_dynamics(crane, xi[None], joints.position, joints.velocity, joints.acceleration, weight)[0][
        0
    ]
    crane_side = design_structure(crane, emlas, lengths, joints, force, weight)
    inverse = make_machine_dynamics(machine, list(xi), "newton_euler")
    machine_side = machine_design_structure(machine, inverse, emlas, joints, weight)
    assert set(machine_side.pins) == set(XS031_PINS)
    for name, crane_name in XS031_PINS.items():
        mine, theirs = machine_side.pins[name], crane_side.pins[crane_name]
        for key in ("peak_N", "vector_range_N", "magnitude_range_N"):
            assert getattr(mine, key) == pytest.approx(getattr(theirs, key), rel=1e-9), f"{name} {key}"
        assert mine.peak_direction_rad == pytest.approx(theirs.peak_direction_rad, abs=1e-9), name  # bracket frame
    assert machine_side.most_loaded_pin == "lift.base_pin" and crane_side.most_loaded_pin == "lift.base_pivot"
    for name, theirs in crane_side.buckling.items():
        mine = machine_side.buckling[name]
        assert mine.max_utilisation == pytest.approx(theirs.max_utilisation, rel=1e-9), name
        assert mine.max_column_length_m == pytest.approx(theirs.max_column_length_m, rel=1e-12), name
    assert machine_side.lowest_frequency_trajectory_Hz == pytest.approx(
        crane_side.lowest_frequency_trajectory_Hz, rel=1e-9
    )


def test_excavator_pins_and_mass_matrix_agree_on_both_id_paths(excavator: tuple[Machine, object]) -> None:
    machine, emlas = excavator
    joints = _random_motion(machine, 2, 30)
    force = np.array([800.0, -2500.0])
    paths = {p: make_machine_dynamics(machine, None, p) for p in ("newton_euler", "mujoco")}
    q, dq, ddq = joints.position, joints.velocity, joints.acceleration
    loads = {p: machine_pin_loads(machine, q, inv(q, dq, ddq, force).pins) for p, inv in paths.items()}
    a, b = loads["newton_euler"], loads["mujoco"]
    assert [pin.name for pin in a.pins] == list(machine_pin_names(machine))
    scale = float(np.max(a.magnitude))
    assert float(np.max(np.abs(a.force_world - b.force_world))) < 1e-9 * scale
    masses = {p: mass_matrix(inv, q, actuator_jacobian(inv, q)) for p, inv in paths.items()}
    assert np.allclose(masses["newton_euler"], masses["mujoco"], rtol=1e-9, atol=1e-9 * np.max(masses["mujoco"]))
    ne = machine_natural_frequencies(machine, paths["newton_euler"], emlas, q, force, payload_kg=60.0)
    mj = machine_natural_frequencies(machine, paths["mujoco"], emlas, q, force, payload_kg=60.0)
    assert np.allclose(ne.frequency_Hz, mj.frequency_Hz, rtol=1e-9)
    heavier = machine_natural_frequencies(machine, paths["newton_euler"], emlas, q, force, payload_kg=200.0)
    assert np.all(heavier.lowest_Hz < ne.lowest_Hz)  # a heavier payload lowers every pose's first mode


def test_excavator_frequency_matches_a_free_vibration_of_the_spring_mounted_mujoco_model(
    excavator: tuple[Machine, object],
) -> None:
    """The FFT peak of a small free vibration (RK4, springs on the rod slides) within 1 % of the eigenvalue."""
    machine, emlas = excavator
    pose = np.array([0.3, -1.6, -0.8])
    for mode in (0, 1):
        simulated, eigen = machine_free_vibration_frequency(
            machine, emlas, pose, FreeVibration(mode=mode, periods=20.0)
        )
        assert simulated == pytest.approx(eigen, rel=0.01), f"mode {mode}"


def test_machine_frequencies_name_the_actuators_the_emla_file_lacks(
    excavator: tuple[Machine, object],
) -> None:
    machine, _emlas = excavator
    inverse = make_machine_dynamics(machine, None, "newton_euler")
    q = _random_motion(machine, 3, 3).position
    with pytest.raises(InvalidInputError, match="no actuator of these names"):
        machine_natural_frequencies(machine, inverse, load_emla_set("xs031"), q)  # lift, tilt, telescope


#: The helper's excavator study, coarser, with every structural row.
STRUCTURE_STUDY = {
    **EXCAVATOR_STUDY,
    "name": "excavator_structure",
    "spline": {"control_points": 8, "degree": 5},
    "grid": {"duration": 4.0, "intervals": 6, "fine_factor": 2},
    "structure": {
        "buckling": True,
        "pin_load_limits": {"boom.base_pin": 60000.0},
        "min_natural_frequency_Hz": 2.0,
    },
}


def test_machine_structure_rows_have_the_gradients_of_central_differences(tmp_path: Path) -> None:
    joint_csv(tmp_path / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(STRUCTURE_STUDY), encoding="utf-8")
    p = StudyProblem(load_study(tmp_path / "study.yaml"))
    names = p.constraint_names
    rows = [i for i, n in enumerate(names) if n.startswith("structure.")]
    for block in ("structure.buckling", "structure.pin_load", "structure.natural_frequency"):
        assert any(names[i].startswith(block) for i in rows), block
    rng = np.random.default_rng(5)
    z0 = p.initial_point(p.study.initial_lengths)
    z0 = z0 + 1e-4 * rng.standard_normal(len(z0)) * (np.arange(len(z0)) >= p.n_xi)
    jac = p.constraints_jacobian(z0)[rows]
    columns = [*range(p.n_xi), *rng.choice(np.arange(p.n_xi, p.n), 5, replace=False)]
    for j in columns:
        up, down, h = central_steps(z0, j)
        d_rows = (p.constraints(up)[rows] - p.constraints(down)[rows]) / (2 * h)
        scale = max(1.0, float(np.max(np.abs(d_rows))))
        assert float(np.max(np.abs(d_rows - jac[:, j]))) < 2e-4 * scale, f"column {j}"
    values = p.constraints(z0)[rows]
    assert np.all(np.isfinite(values))

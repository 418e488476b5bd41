"""The Python API: the README's example runs as written; evaluate's three meanings; bad input names its field."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_study_small import machine_form, small_study

import hiab_sim as hs
from hiab_sim.errors import InvalidInputError

README = Path(__file__).resolve().parents[1] / "README.md"


def _readme_api_block() -> str:
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    found = [b for b in blocks if "import hiab_sim as hs" in b]
    assert found, "the README has no Python example of the API"
    return found[0]


@pytest.mark.e2e
def test_the_readme_python_example_runs_as_written(tmp_path: Path) -> None:
    """The README's API block runs unchanged in a fresh folder and writes the result folder it names."""
    code = _readme_api_block()
    result = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, check=False, timeout=600
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert (tmp_path / "runs" / "x" / "result.json").is_file()


def test_importing_hiab_sim_leaves_the_environment_alone() -> None:
    """``import hiab_sim`` sets no variable (MUJOCO_GL is chosen when rendering starts).

    The child starts without the variables that the package or its dependencies are known to set.
    Loading the solvers (the API's functions) loads threadpoolctl, which sets KMP_DUPLICATE_LIB_OK
    for itself (its workaround for two OpenMP runtimes in one process, which would abort otherwise);
    hiab-sim keeps it and sets nothing else.
    """
    known = ("MUJOCO_GL", "KMP_DUPLICATE_LIB_OK")
    env = {k: v for k, v in os.environ.items() if k not in known}
    code = (
        "import os; before = dict(os.environ); import hiab_sim; print(dict(os.environ) == before); "
        "hiab_sim.evaluate; import hiab_sim.study.run; after = dict(os.environ); "
        "after.pop('KMP_DUPLICATE_LIB_OK', None); print(after == before)"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["True", "True"]


@pytest.fixture(scope="module")
def study() -> hs.api.Study:
    from hiab_sim.study.spec.study_file import study_from_dict

    return study_from_dict(small_study(), "small.yaml")


@pytest.fixture(scope="module")
def run_folder(study: hs.api.Study, tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("api") / "run"
    hs.optimize(study, out=folder, progress=None, figures=False)
    return folder


@pytest.fixture(scope="module")
def optimum(run_folder: Path) -> hs.api.Result:
    return hs.read_result(run_folder)


def test_fixed_evaluation_of_the_start_reproduces_the_results_initial_design(
    study: hs.api.Study, optimum: hs.api.Result
) -> None:
    """evaluate(..., "fixed") at the built crane's lengths gives result.json's initial design, number for number."""
    e = hs.evaluate(study, optimum.initial.lengths, trajectory="fixed")
    assert e.tasks[0].summary.net_electrical_energy_J == pytest.approx(
        optimum.initial.net_electrical_energy_J, rel=1e-12
    )
    assert e.max_violation == pytest.approx(optimum.initial.max_violation, rel=1e-9, abs=1e-12)
    assert optimum.energy is not None
    assert e.battery_energy_J == pytest.approx(optimum.energy.initial.battery_energy_J, rel=1e-12)


def test_evaluation_on_the_optimums_trajectory_at_its_lengths_reproduces_the_results_optimal_design(
    study: hs.api.Study, optimum: hs.api.Result, run_folder: Path
) -> None:
    """evaluate(..., "optimum", result=folder) at the optimal lengths gives result.json's optimal design."""
    e = hs.evaluate(study, optimum.optimal.lengths, trajectory="optimum", result=run_folder)
    assert e.trajectory == "optimum"
    assert e.net_electrical_energy_J == pytest.approx(optimum.optimal.net_electrical_energy_J, rel=1e-12)
    assert optimum.energy is not None
    assert e.battery_energy_J == pytest.approx(optimum.energy.optimal.battery_energy_J, rel=1e-12)
    assert e.max_violation == pytest.approx(optimum.optimal.max_violation, rel=1e-9, abs=1e-12)


def test_another_design_on_the_optimums_trajectory_moves_the_actuators_not_the_tcp(
    study: hs.api.Study, optimum: hs.api.Result, run_folder: Path
) -> None:
    """A base pivot 20 mm nearer its hinge, driven on the optimum's motion: the TCP errors stay the optimum's.

    The crane's TCP kinematics do not depend on Xi; the actuator forces and the energy do. The start's
    trajectory ("fixed") at the same lengths is another motion, with other TCP errors.
    """
    lengths = optimum.optimal.lengths.as_array().copy()
    lengths[0] -= 0.02  # lift L [m]
    moved = hs.evaluate(study, lengths, trajectory="optimum", result=run_folder).tasks[0].summary
    fixed = hs.evaluate(study, lengths, trajectory="fixed").tasks[0].summary
    at_optimum = optimum.optimal
    assert moved.tracking_error.position_m == pytest.approx(at_optimum.tracking_error.position_m, rel=1e-12)
    assert moved.tracking_error.position_m != pytest.approx(fixed.tracking_error.position_m, rel=1e-6)
    assert abs(moved.net_electrical_energy_J - at_optimum.net_electrical_energy_J) > 1.0  # [J]
    lift = moved.actuators["lift"]
    assert lift.peak_force_N != pytest.approx(at_optimum.actuators["lift"].peak_force_N, rel=1e-6)


def test_the_optimums_trajectory_needs_a_finished_result_folder_of_the_same_study(
    study: hs.api.Study, run_folder: Path, tmp_path: Path
) -> None:
    """No folder, an unfinished one, another study's, or a folder with "fixed": each one line naming ``result``."""
    import json

    lengths = study.initial_lengths
    other = tmp_path / "other"
    other.mkdir()
    (other / "checkpoint_0.json").write_text(json.dumps({"done": True, "study_sha256": "0" * 64, "z": []}))
    cases = [
        ({"trajectory": "optimum"}, "None"),
        ({"trajectory": "optimum", "result": tmp_path}, "finished optimisation"),
        ({"trajectory": "optimum", "result": other}, "another study"),
        ({"trajectory": "fixed", "result": run_folder}, 'only with trajectory="optimum"'),
    ]
    for kwargs, words in cases:
        with pytest.raises(InvalidInputError) as error:
            hs.evaluate(study, lengths, **kwargs)  # type: ignore[arg-type]
        assert error.value.field == "result" and words in str(error.value) and "\n" not in str(error.value)


def test_reoptimised_evaluation_of_the_optimum_recovers_its_energy_and_beats_the_fixed_trajectory(
    study: hs.api.Study, optimum: hs.api.Result
) -> None:
    """Re-planning the optimum's trajectory at its lengths lands on the optimum (a local optimum of the same NLP).

    The optimal lengths on the start's inverse-kinematics trajectory ("fixed") cost more than with the
    trajectory re-optimised for them, and the re-optimised one is feasible.
    """
    pytest.importorskip("casadi")
    lengths = optimum.optimal.lengths.as_array()
    again = hs.evaluate(study, lengths, trajectory="reoptimize")
    fixed = hs.evaluate(study, {"lift": lengths[:3], "tilt": lengths[3:]}, trajectory="fixed")
    assert again.feasible
    assert again.net_electrical_energy_J == pytest.approx(optimum.optimal.net_electrical_energy_J, rel=1e-3)
    assert again.tasks[0].summary.cost_W2s <= fixed.tasks[0].summary.cost_W2s


def test_a_design_outside_its_bounds_is_named_by_the_bound_it_crosses(
    study: hs.api.Study, optimum: hs.api.Result
) -> None:
    """The optimum with lift.Lc0 10 mm above its upper bound (0.30 m): the least margin is that bound's, -0.01 m.

    Every row holds there (the violation is the bound's alone), so no other limit can be the worst; a
    satisfied row was named before.
    """
    lengths = optimum.optimal.lengths.as_array().copy()
    assert lengths[1] == pytest.approx(0.3, abs=1e-6)  # the small study's optimum sits on this bound
    lengths[1] = 0.31  # lift Lc0 [m]
    task = hs.evaluate(study, lengths, trajectory="fixed").tasks[0]
    assert not task.feasible
    worst = task.summary.worst_constraint
    assert worst.name == "bound lift.Lc0 up = 0.3 m"
    assert worst.scaled_margin == pytest.approx(-0.01, abs=1e-12)
    assert task.summary.max_violation == pytest.approx(0.01, abs=1e-12)


def test_a_design_out_of_its_chains_reach_names_the_lengths_that_moved(study: hs.api.Study) -> None:
    """lift.L 10 mm past its bound: the chain cannot serve its working range; the line names the chain's lengths."""
    lengths = study.initial_lengths.as_array().copy()
    lengths[0] = 1.26  # lift L [m]
    with pytest.raises(InvalidInputError) as error:
        hs.evaluate(study, lengths, trajectory="fixed")
    message = str(error.value)
    assert "\n" not in message and message.startswith("lift.")
    assert f"at lift L / Lc0 / Lc = 1.26 / {lengths[1]:.6g} / {lengths[2]:.6g} m" in message


@pytest.mark.parametrize(
    ("lengths", "trajectory", "field"),
    [
        (np.ones(5), "fixed", "lengths"),
        ({"lift": [1.0, 0.3, 0.7]}, "fixed", "lengths"),
        ({"lift": [1.0, 0.3], "tilt": [1.2, 0.3, 0.6]}, "fixed", "lengths.lift"),
        (np.ones(6), "replan", "trajectory"),
    ],
)
def test_bad_evaluate_input_names_the_field(study: hs.api.Study, lengths: object, trajectory: str, field: str) -> None:
    """Wrong-shaped lengths or an unknown trajectory meaning: InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as error:
        hs.evaluate(study, lengths, trajectory=trajectory)  # type: ignore[arg-type]
    assert error.value.field == field


def test_a_wrongly_shaped_array_is_named_on_one_line(study: hs.api.Study) -> None:
    """A (2, 3) array for the six lengths: one line showing its values (numpy prints rows on separate lines)."""
    with pytest.raises(InvalidInputError) as error:
        hs.evaluate(study, np.ones((2, 3)))
    assert "\n" not in str(error.value)
    assert str(error.value).startswith(
        "lengths = [[1.0, 1.0, 1.0], [1.0, 1.0, 1.0]] m is out of range: must be 6 values"
    )


@pytest.mark.parametrize("starts", [0, -1, 1.5, "2", True])
def test_optimize_refuses_starts_that_are_not_a_positive_integer(
    study: hs.api.Study, tmp_path: Path, starts: object
) -> None:
    """``starts`` below 1 or not an integer: InvalidInputError naming ``starts``, before any folder is written."""
    with pytest.raises(InvalidInputError) as error:
        hs.optimize(study, out=tmp_path / "run", starts=starts, progress=None, figures=False)  # type: ignore[arg-type]
    assert error.value.field == "starts"
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("call", [lambda: hs.load_study(3), lambda: hs.evaluate(3, [1.0] * 6)])  # type: ignore[arg-type]
def test_a_study_that_is_neither_a_name_nor_a_path_is_named(call: object) -> None:
    """A number for the study: InvalidInputError naming ``study`` (was a TypeError from inside pathlib)."""
    with pytest.raises(InvalidInputError) as error:
        call()  # type: ignore[operator]
    assert error.value.field == "study"


@pytest.fixture(scope="module")
def machine_study() -> hs.api.Study:
    """The small study on the XS 031's machine file (its own bounds; tracking the telescope's extension)."""
    from hiab_sim.study.spec.study_file import study_from_dict

    return study_from_dict(machine_form(small_study()), "small_machine.yaml")


def test_a_machine_files_study_evaluates_its_own_design_in_every_form(
    study: hs.api.Study, machine_study: hs.api.Study
) -> None:
    """Evaluate takes a machine file's design typed, as values, by chain or by ``chain.variable``.

    Each form gives the same numbers, and those agree with the crane file's closed-form model at the
    same lengths (two independent descriptions of the XS 031: 1e-9 relative).
    """
    design = machine_study.model.default_design
    names, values = machine_study.model.design_names, design.as_array()
    by_variable = dict(zip(names, values, strict=True))
    by_chain = {"lift": values[:3], "tilt": values[3:]}
    energies = {
        form: hs.evaluate(machine_study, given, trajectory="fixed").net_electrical_energy_J
        for form, given in (("typed", design), ("values", values), ("variables", by_variable), ("chains", by_chain))
    }
    assert len(set(energies.values())) == 1, energies
    crane = hs.evaluate(study, values, trajectory="fixed")
    assert energies["typed"] == pytest.approx(crane.net_electrical_energy_J, rel=1e-9)


@pytest.mark.parametrize(
    ("given", "message"),
    [
        ({"lift.L": 1.0}, r"misses \['lift.Lc0'"),
        ({"boom.L": 1.0}, r"keys are the chains \['lift', 'tilt'\]"),
        (np.ones(9), r"must be 6 values, in order \['lift.L'"),
        ({"lift.L": [1.0, 2.0], "lift": [1.0, 0.1, 0.7]}, r"lengths.lift .*not both"),
        ({"lift": [1.0, 0.1, 0.7], "tilt": [1.1, 0.1, 0.7], "lift.L": 1.0}, r"lengths.lift .*not both"),
        ({"lift": ["a", 0.1, 0.7], "tilt": [1.1, 0.1, 0.7]}, r"lengths.lift "),
        ({"lift.L": [1.0, 2.0]}, r"lengths.lift.L .*one finite number"),
        (["1.0", "x", 0, 0, 0, 0], r"lengths .*must be 6 values"),
        ([1.0, float("nan"), 0.7, 1.1, 0.1, 0.7], r"lengths .*must be 6 values"),
    ],
)
def test_a_design_that_is_not_the_machines_names_what_it_needs(
    machine_study: hs.api.Study, given: object, message: str
) -> None:
    """A missing variable, another machine's variable or the wrong count: one line naming the study's variables."""
    with pytest.raises(InvalidInputError, match=message):
        hs.evaluate(machine_study, given)  # type: ignore[arg-type]

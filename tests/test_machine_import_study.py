"""A shipped machine exported and read back: ``hiab-sim mjcf --machine`` then ``machine import``, no edit between.

The exported MJCF carries the working ranges and strokes as limited joint ranges and a
loop-consistent keyframe, so the import reads it as written. The imported file must give the
original machine file's actuator forces (two descriptions built independently: the original's
frames and bodies, and MuJoCo's compiled reading of the exported XML re-expressed by the import),
and, once its proposed decision variables are replaced by the original's equivalent ones, the
original's studies and their optimum.
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import sys
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
import yaml

from hiab_sim.cli import main
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.paths import MACHINE_ID_PATHS, make_machine_dynamics
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine_mjcf import machine_mjcf, working_ranges
from hiab_sim.resources import locate

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine_result_helper import EXCAVATOR_STUDY, joint_csv
from test_machine_study import REPO, _machine_form

#: Relative actuator-force agreement the import must reach (per actuator, of its peak force).
TOLERANCE = 1e-9
SHIPPED = ("xs031", "exact")


def _cli(*args: str) -> tuple[int, str]:
    """Run ``hiab-sim`` with ``args``; its exit status and what it printed."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = main(list(args))
    return status, out.getvalue()


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, list[float]]]:
    """Per shipped machine: what ``machine import`` wrote from ``mjcf --machine``'s XML, and its printed round trip."""
    folder = tmp_path_factory.mktemp("exported")
    out = {}
    for name in SHIPPED:
        xml, machine_file = folder / f"{name}.xml", folder / f"{name}_imported.yaml"
        assert _cli("mjcf", "--machine", name, "-o", str(xml))[0] == 0
        status, printed = _cli("machine", "import", str(xml), "-o", str(machine_file), "--samples", "12")
        assert status == 0, printed
        rounds = [float(line.rsplit(" ", 1)[1]) for line in printed.splitlines() if line.startswith("round trip")]
        out[name] = (machine_file, rounds)
    return out


def _random_states(machine: Machine, rng: np.random.Generator, samples: int) -> tuple[np.ndarray, ...]:
    """Joint states inside the working ranges (within what the chains reach), rates, accelerations, TCP forces."""
    ranges = np.array(working_ranges(machine))
    q = ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.uniform(0.02, 0.98, (samples, len(ranges)))
    return q, rng.normal(0.0, 0.5, q.shape), rng.normal(0.0, 1.0, q.shape), rng.normal(0.0, 1000.0, (samples, 2))


def _largest_force_difference(mine: Machine, theirs: Machine, seed: int, design: Any = None) -> float:
    """Largest relative actuator-force difference, every pairing of the two ID paths of the two machines."""
    q, dq, ddq, tcp = _random_states(
        theirs if design is None else theirs.with_design(design), np.random.default_rng(seed), 16
    )
    worst = 0.0
    for path in MACHINE_ID_PATHS:
        reference = make_machine_dynamics(theirs, design, path)(q, dq, ddq, tcp).force
        peak = np.max(np.abs(reference), axis=0)
        for other in MACHINE_ID_PATHS:
            force = make_machine_dynamics(mine, design, other)(q, dq, ddq, tcp).force
            worst = max(worst, float(np.max(np.max(np.abs(force - reference), axis=0) / peak)))
    return worst


def _variable_kinds(chains: dict[str, Any]) -> dict[str, set[tuple[str, str | None]]]:
    """Per chain, the (kind, pivot) of each declared decision variable (what a variable moves, not its name)."""
    return {
        name: {(v["kind"], v.get("pivot")) for v in entry.get("variables", {}).values()}
        for name, entry in chains.items()
    }


def _original_yaml(name: str) -> dict[str, Any]:
    return yaml.safe_load(Path(str(locate(name, "machine").file)).read_text(encoding="utf-8"))


def adopt_original_variables(machine_file: Path, name: str, out: Path) -> Path:
    """The imported file with the original's decision variables (names, bounds) and body scaling: the user's edit.

    The import proposes variables of the same kinds on the same pivots (``_variable_kinds``) with
    bounds around the imported values, and ``body_scaling: fixed`` (an MJCF does not say how a
    cylinder's body grows with its length). A machine file's study takes its variables and bounds
    from the machine file, so the same study frees the same variables only once the file declares
    them as the original does.
    """
    data = yaml.safe_load(machine_file.read_text(encoding="utf-8"))
    original = _original_yaml(name)["chains"]
    for chain, entry in data["chains"].items():
        theirs = original[chain]
        entry.pop("variables", None)
        if "variables" in theirs:
            entry["variables"] = theirs["variables"]
        entry["actuator"]["body_scaling"] = theirs["actuator"].get("body_scaling", "slender")
    out.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return out


@pytest.mark.parametrize("name", SHIPPED)
def test_the_exported_mjcf_limits_its_joints_to_the_working_ranges_and_strokes_only_outside_them(name: str) -> None:
    """Hinges at their working ranges, slides at [0, stroke], chain hinges free; inside, no limit acts.

    At the keyframe ``home`` the ``connect`` pins close and MuJoCo instantiates no limit row; it
    does at random poses inside the ranges neither, and does once a joint is moved past its range.
    """
    machine = load_machine(name)
    model = mujoco.MjModel.from_xml_string(machine_mjcf(machine))
    limited = {model.joint(j).name: tuple(model.jnt_range[j]) for j in range(model.njnt) if model.jnt_limited[j]}
    expected = {j: machine.joint_link(j).joint_range for j in machine.joint_names}
    for chain in machine.chains:
        expected[f"{chain.name}.stroke" if chain.kind != "direct" else chain.joint] = (0.0, chain.actuator.stroke)
    assert limited == {k: tuple(v) for k, v in expected.items()}
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    for e in range(model.neq):
        a, b = (data.site_xpos[model.eq_obj1id[e]], data.site_xpos[model.eq_obj2id[e]])
        assert np.linalg.norm(a - b) < 1e-12
    assert mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT not in data.efc_type[: data.nefc]
    joint = model.joint(machine.joint_names[0])
    data.qpos[joint.qposadr[0]] = model.jnt_range[joint.id][1] + 1e-3
    mujoco.mj_forward(model, data)
    assert mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT in data.efc_type[: data.nefc]


@pytest.mark.e2e
@pytest.mark.parametrize("name", SHIPPED)
def test_importing_the_exported_mjcf_gives_the_original_machines_forces(
    name: str, imported: dict[str, tuple[Path, list[float]]]
) -> None:
    """The printed round trip (vs the MJCF) and the original machine file's forces (both paths) agree to 1e-9."""
    machine_file, rounds = imported[name]
    assert len(rounds) == 2 and max(rounds) < TOLERANCE
    mine, theirs = load_machine(machine_file), load_machine(name)
    assert mine.joint_names == theirs.joint_names and mine.actuator_names == theirs.actuator_names
    assert [c.kind for c in mine.chains] == [c.kind for c in theirs.chains]
    for joint in theirs.joint_names:
        assert mine.joint_link(joint).joint_range == pytest.approx(theirs.joint_link(joint).joint_range, abs=1e-12)
    for a, b in zip(mine.chains, theirs.chains, strict=True):
        assert a.actuator.stroke == pytest.approx(b.actuator.stroke, abs=1e-12)
    assert _largest_force_difference(mine, theirs, seed=11) < TOLERANCE


@pytest.mark.e2e
@pytest.mark.parametrize("name", SHIPPED)
def test_the_proposed_variables_are_the_originals_and_keep_its_forces_at_every_design(
    name: str, imported: dict[str, tuple[Path, list[float]]], tmp_path: Path
) -> None:
    """Same kinds on the same pivots; with the original's names and bounds: its values, and its forces off the default.

    Equal forces at random designs inside the bounds (the pivots moved, the cylinders and rods
    rescaled) show that the two parametrisations are one: the same design vector builds the same
    machine from either file.
    """
    machine_file, _ = imported[name]
    proposal = yaml.safe_load(machine_file.read_text(encoding="utf-8"))["chains"]
    assert _variable_kinds(proposal) == _variable_kinds(_original_yaml(name)["chains"])
    mine = load_machine(adopt_original_variables(machine_file, name, tmp_path / "adopted.yaml"))
    theirs = load_machine(name)
    assert mine.variable_keys == theirs.variable_keys
    assert [(v.low, v.high) for v in mine.decision_variables] == [(v.low, v.high) for v in theirs.decision_variables]
    assert np.max(np.abs(np.subtract(mine.design_values(), theirs.design_values()))) < 1e-12
    for k, design in enumerate(_assembling_designs(theirs, 3)):
        assert _largest_force_difference(mine, theirs, seed=k, design=design) < TOLERANCE


def _assembling_designs(machine: Machine, count: int) -> list[np.ndarray]:
    """``count`` random designs inside the bounds whose every chain assembles somewhere in its working range."""
    from hiab_sim.errors import InvalidInputError

    rng = np.random.default_rng(5)
    low = np.array([v.low for v in machine.decision_variables])
    high = np.array([v.high for v in machine.decision_variables])
    found = []
    for _ in range(50):
        design = low + (high - low) * rng.uniform(0.05, 0.95, low.size)
        try:
            working_ranges(machine.with_design(design))
        except InvalidInputError:
            continue  # a chain that does not close at this design: no state to compare
        found.append(design)
        if len(found) == count:
            return found
    raise AssertionError(f"fewer than {count} of 50 random designs assemble")


def _xs031_default_studies(imported: dict[str, tuple[Path, list[float]]], folder: Path) -> tuple[Path, Path]:
    """The default study in the machine-file form on the shipped machine file, and on the imported one."""
    text = _machine_form((REPO / "optimize" / "xs031_spiral.yaml").read_text(encoding="utf-8"))
    adopted = adopt_original_variables(imported["xs031"][0], "xs031", folder / "xs031_adopted.yaml")
    original, mine = folder / "original.yaml", folder / "imported.yaml"
    original.write_text(text, encoding="utf-8")
    mine.write_text(text.replace("machine: xs031", f"machine: {adopted}"), encoding="utf-8")
    return original, mine


@pytest.mark.e2e
def test_the_imported_xs031_default_study_is_the_original_nlp(
    imported: dict[str, tuple[Path, list[float]]], tmp_path: Path
) -> None:
    """At a perturbed point, the imported file's default study has the original's cost, rows and cost gradient."""
    _same_nlp(*_xs031_default_studies(imported, tmp_path))


def _same_nlp(original: Path, mine: Path) -> None:
    """Both study files' NLPs at a perturbed start: cost to 1e-10, rows to 1e-10 of the largest, gradient to 1e-8."""
    from hiab_sim.study.nlp.problem import StudyProblem
    from hiab_sim.study.spec.study_file import load_study

    a, b = (StudyProblem(load_study(path)) for path in (original, mine))
    assert a.n == b.n and a.constraint_names == b.constraint_names
    z = a.initial_point(a.study.initial_lengths)
    z = z + 1e-3 * np.random.default_rng(3).standard_normal(len(z))
    ev_a, ev_b = a.evaluate(z), b.evaluate(z)
    assert ev_b.cost == pytest.approx(ev_a.cost, rel=1e-10)
    scale = max(1.0, float(np.max(np.abs(ev_a.constraints))))
    assert float(np.max(np.abs(ev_b.constraints - ev_a.constraints))) < 1e-10 * scale
    grad_a = a.cost_gradient(z)
    assert float(np.max(np.abs(b.cost_gradient(z) - grad_a))) < 1e-8 * float(np.max(np.abs(grad_a)))


def _same_optimum(
    original: Path,
    mine: Path,
    folder: Path,
    xi_m: float = 1e-8,
    energy: float = 1e-9,
    net: float = 1e-9,
    iterations: bool = True,
) -> tuple[Any, Any]:
    """Both studies solved: Xi within ``xi_m`` [m], battery and net energies within ``energy``, ``net`` (relative)."""
    from hiab_sim.study.run import run_study
    from hiab_sim.study.spec.study_file import load_study

    a = run_study(load_study(original), folder / "original", progress=None, figures=False).result
    b = run_study(load_study(mine), folder / "imported", progress=None, figures=False).result
    assert a.solver.success and b.solver.success
    assert b.optimal.lengths.names == a.optimal.lengths.names
    assert np.max(np.abs(b.optimal.lengths.as_array() - a.optimal.lengths.as_array())) < xi_m
    assert b.solver.iterations == a.solver.iterations or not iterations
    assert a.energy is not None and b.energy is not None
    assert b.energy.optimal.battery_energy_J == pytest.approx(a.energy.optimal.battery_energy_J, rel=energy)
    assert b.optimal.net_electrical_energy_J == pytest.approx(a.optimal.net_electrical_energy_J, rel=net)
    return a, b


@pytest.mark.e2e
def test_the_imported_xs031_default_study_reaches_the_original_optimum(
    imported: dict[str, tuple[Path, list[float]]], tmp_path: Path
) -> None:
    """The default study (machine-file form) on the imported file: the original's Xi, iterations and energies."""
    original, mine = _xs031_default_studies(imported, tmp_path)
    _same_optimum(original, mine, tmp_path)


@pytest.mark.slow
def test_the_imported_excavator_digging_study_reaches_the_original_optimum(
    imported: dict[str, tuple[Path, list[float]]], tmp_path: Path
) -> None:
    """``optimize/exact_digging.yaml`` on the imported eXact file: the original's NLP, and its optimum.

    The two NLPs agree at a point to round-off; IPOPT's path then ends micrometres apart along the
    bucket's base pin, the flat direction of this optimum (measured on 7 December 2026: 3.2e-6 m, the
    battery energy, the objective, 1.2e-8 relative apart, the net electrical energy 2.9e-7; the
    study's own three starts spread by 3.5e-5 m): Xi within the multistart's same-optimum tolerance
    (1e-4 m), the objective within 1e-7 (IPOPT's stop: scaled NLP error 1e-8), the net energy 1e-5.
    """
    text = (REPO / "optimize" / "exact_digging.yaml").read_text(encoding="utf-8")
    shutil.copy(REPO / "optimize" / "exact_digging_cycle.csv", tmp_path / "exact_digging_cycle.csv")
    adopted = adopt_original_variables(imported["exact"][0], "exact", tmp_path / "exact_adopted.yaml")
    original, mine = tmp_path / "original.yaml", tmp_path / "imported.yaml"
    original.write_text(text, encoding="utf-8")
    mine.write_text(text.replace("machine: exact ", f"machine: {adopted} "), encoding="utf-8")
    assert str(adopted) in mine.read_text(encoding="utf-8")
    _same_nlp(original, mine)
    _same_optimum(original, mine, tmp_path, xi_m=1e-4, energy=1e-7, net=1e-5, iterations=False)


@pytest.mark.e2e
def test_optimize_and_simulate_run_on_an_imported_machine(
    imported: dict[str, tuple[Path, list[float]]], tmp_path: Path
) -> None:
    """The imported eXact file as written (its proposed variables): a small study optimises and closes the loop.

    A 4 s joint move with 12 control points; ``simulate --no-video`` on the optimum: the closed
    loop uses the plan's energy within the command's 2 %.
    """
    from hiab_sim.cli.simulate import ENERGY_TOLERANCE

    joint_csv(tmp_path / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({**EXCAVATOR_STUDY, "machine": str(imported["exact"][0])}), encoding="utf-8")
    run = tmp_path / "run"
    flags = ("--no-video", "--no-figures", "--quiet")
    assert _cli("optimize", str(study), "--out", str(run), "--no-report", *flags)[0] == 0
    result = json.loads((run / "result.json").read_text(encoding="utf-8"))
    assert result["solver"]["success"]
    assert result["optimal"]["lengths"]["names"] == load_machine(imported["exact"][0]).variable_keys
    assert _cli("simulate", str(run), "--design", "optimal", "--out", str(tmp_path / "sim"), *flags)[0] == 0
    report = json.loads((tmp_path / "sim" / "simulation.json").read_text(encoding="utf-8"))
    entry = report["designs"]["optimal"]
    assert set(entry["actuators"]) == {"boom", "arm", "bucket"}
    assert abs(entry["energy_difference_percent"]) < 100 * ENERGY_TOLERANCE

"""A study of a machine file (``machine:``): the same NLP as a crane file's, sized and named by the machine.

Two independent descriptions of the XS 031 (the crane file's closed-form model and the machine file's
generic tree, tracked kinematics and Newton-Euler) must give the same NLP; on the excavator, whose
bucket is a four-bar the crane model cannot describe, the gradients must match finite differences.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from differences_helper import central_steps
from machine_result_helper import EXCAVATOR_STUDY, joint_csv

from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_setup import start_error
from hiab_sim.study.spec.study_file import load_study, study_from_dict

REPO = Path(__file__).resolve().parents[1]


def _tcp_csv(path: Path, kin_study: object, joints: Path) -> None:
    """The TCP form (t, x, y, xt2) of a joint move, through the crane's own kinematics."""
    data = np.loadtxt(joints, delimiter=",", comments="#", skiprows=2)
    kin = kin_study.model.kinematics  # type: ignore[attr-defined]
    s = kin.samples(data[:, 1:], np.zeros_like(data[:, 1:]), np.zeros_like(data[:, 1:]))
    lines = ["# the TCP of a test move", "t,x,y,xt2"]
    lines += [",".join(f"{v:.12g}" for v in row) for row in np.column_stack([data[:, 0], s.position])]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _study(folder: Path, top: dict[str, object]) -> object:
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(top), encoding="utf-8")
    return load_study(path)


@pytest.fixture(scope="module")
def excavator(tmp_path_factory: pytest.TempPathFactory) -> StudyProblem:
    folder = tmp_path_factory.mktemp("excavator")
    joint_csv(folder / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    return StudyProblem(_study(folder, EXCAVATOR_STUDY))  # type: ignore[arg-type]


def test_excavator_problem_is_sized_and_named_by_its_machine_file(excavator: StudyProblem) -> None:
    model = excavator.model
    assert model.joint_names == ("alpha", "beta", "gamma")
    assert model.tracked_names == ("x_tcp", "y_tcp", "tcp_angle")
    assert excavator.n_xi == 9 and excavator.emlas.names == ("boom", "arm", "bucket")
    names = excavator.constraint_names
    assert any(n.startswith("stroke.bucket.x <= stroke") for n in names)  # the four-bar's stroke rows
    assert any(n.startswith("envelope.arm.") for n in names)
    assert any(n.startswith("tracking.position.tcp_angle") for n in names)
    z = excavator.initial_point(excavator.study.initial_lengths)
    assert excavator.max_violation(z) < 1e-9  # the IK fit tracks its own reference at the file's design


def test_excavator_gradients_match_central_differences(excavator: StudyProblem) -> None:
    """Cost and rows: the exact-structure gradient against central differences of the whole NLP in z."""
    p = excavator
    rng = np.random.default_rng(7)
    z0 = p.initial_point(p.study.initial_lengths)
    z0 = z0 + 1e-3 * rng.standard_normal(len(z0)) * (np.arange(len(z0)) >= p.n_xi)  # off the fit
    grad, jac = p.cost_gradient(z0), p.constraints_jacobian(z0)
    columns = [*range(p.n_xi), *rng.choice(np.arange(p.n_xi, p.n), 6, replace=False)]
    for j in columns:
        up, down, h = central_steps(z0, j)
        d_cost = (p.cost(up) - p.cost(down)) / (2 * h)
        d_rows = (p.constraints(up) - p.constraints(down)) / (2 * h)
        assert d_cost == pytest.approx(grad[j], rel=2e-4, abs=1e-6), f"cost column {j}"
        scale = max(1.0, float(np.max(np.abs(d_rows))))
        assert float(np.max(np.abs(d_rows - jac[:, j]))) < 2e-4 * scale, f"rows column {j}"


def test_xs031_machine_file_and_crane_file_give_the_same_nlp(tmp_path: Path) -> None:
    """The XS 031 through its machine file (tracking xt2) equals the crane file's NLP at a perturbed point."""
    joint_csv(tmp_path / "joints.csv", ("theta1", "theta2", "xt2"), [0.3, -1.5, 0.2], [0.9, -1.0, 0.6], 4.0)
    common = {
        "spline": {"control_points": 12, "degree": 5},
        "grid": {"duration": 4.0, "intervals": 12, "fine_factor": 4},
        "emla": "default",
        "tasks": [{"name": "move", "weight": 1, "reference": {"kind": "csv", "file": "move.csv"}, "payload": 100.0}],
    }
    crane = _study(
        tmp_path,
        {
            **common,
            "name": "a",
            "crane": "xs031",
            "bounds": {
                "lift": {"low": [0.80, 0.04, 0.60], "up": [1.25, 0.30, 1.00]},
                "tilt": {"low": [0.90, 0.04, 0.60], "up": [1.35, 0.30, 1.00]},
                "working_range": "reference",
            },
        }
        | {"tasks": [{"name": "move", "weight": 1, "reference": {"kind": "csv", "file": "joints.csv"}}]},
    )
    _tcp_csv(tmp_path / "move.csv", crane, tmp_path / "joints.csv")
    both = {}
    for key, extra in (
        (
            "crane",
            {
                "crane": "xs031",
                "bounds": {
                    "lift": {"low": [0.80, 0.04, 0.60], "up": [1.25, 0.30, 1.00]},
                    "tilt": {"low": [0.90, 0.04, 0.60], "up": [1.35, 0.30, 1.00]},
                    "working_range": "reference",
                },
            },
        ),
        (
            "machine",
            {
                "machine": "xs031",
                "tracked": ["xt2"],
                "bounds": {"joint_velocity": [0.6, 0.6, 0.5], "working_range": "reference"},
            },
        ),
    ):
        both[key] = StudyProblem(_study(tmp_path, {**common, "name": key, **extra}))  # type: ignore[arg-type]
    a, b = both["crane"], both["machine"]
    assert a.n == b.n and a.model.design_names == b.model.design_names
    z = a.initial_point(a.study.initial_lengths)
    z = z + 1e-3 * np.random.default_rng(3).standard_normal(len(z))
    ev_a, ev_b = a.evaluate(z), b.evaluate(z)
    assert ev_b.cost == pytest.approx(ev_a.cost, rel=1e-10)
    rows_a, rows_b = (
        dict(zip(a.constraint_names, ev_a.constraints, strict=True)),
        dict(zip(b.constraint_names, ev_b.constraints, strict=True)),
    )
    # every row of the machine file's NLP is the crane's, but the joint rows (the crane adds its
    # triangle margin to the joint bounds)
    shared = [n for n in rows_b if not n.startswith("joint.")]
    assert set(shared) == {n for n in rows_a if not n.startswith("joint.")}
    assert max(abs(rows_a[n] - rows_b[n]) for n in shared) < 1e-8
    assert np.allclose(b.cost_gradient(z), a.cost_gradient(z), rtol=1e-6, atol=1e-9)


def test_machine_study_refuses_what_it_cannot_take_with_one_line(tmp_path: Path) -> None:
    joint_csv(tmp_path / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    base = dict(EXCAVATOR_STUDY)
    with pytest.raises(ConfigError, match="kind: csv"):
        study_from_dict(
            {
                **base,
                "tasks": [
                    {
                        "name": "s",
                        "weight": 1,
                        "reference": {
                            "kind": "spiral",
                            "start_radius": 0.1,
                            "end_radius": 0.2,
                            "turns": 1,
                            "telescope_start": 0.0,
                            "centre_tcp": [2.0, 0.0],
                        },
                    }
                ],
            },
            tmp_path / "s.yaml",
        )
    with pytest.raises(ConfigError, match="'crane' and 'machine' name the same thing"):
        study_from_dict({**base, "crane": "xs031"}, tmp_path / "s.yaml")
    with pytest.raises(ConfigError, match="names its EMLA file"):
        study_from_dict({k: v for k, v in base.items() if k != "emla"}, tmp_path / "s.yaml")
    with pytest.raises(ConfigError, match=r"bounds\.joint_velocity: expected a list of 3"):
        study_from_dict({**base, "bounds": {"joint_velocity": [0.6, 0.6]}}, tmp_path / "s.yaml")
    with pytest.raises(InvalidInputError, match="tracked"):
        study_from_dict({**base, "tracked": ["theta9"]}, tmp_path / "s.yaml")
    with pytest.raises(ConfigError, match="'tracked' belongs to a machine file"):
        study_from_dict({"crane": "xs031", "tracked": ["xt2"], "bounds": {}}, tmp_path / "s.yaml")


def test_a_reference_inside_the_id_slack_is_refused_naming_the_reference_not_the_start(tmp_path: Path) -> None:
    """working_range: machine: the reference must keep ID_SLACK from the range's ends; the error says so.

    alpha's range is [-0.4737, 1.0923] rad: a move to 1.08 rad lies in it (as the CSV check sees) but
    within the inverse dynamics' 0.02 rad margin, so the optimiser refuses it, naming the task's file
    and joint, never ``initial_lengths`` or a crane.
    """
    joint_csv(tmp_path / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [1.08, -1.3, -0.3], 4.0)
    bounds = {"joint_velocity": [0.6, 0.6, 1.0], "working_range": "machine"}
    study = _study(tmp_path, {**EXCAVATOR_STUDY, "bounds": bounds})
    with pytest.raises(InvalidInputError) as caught:
        StudyProblem(study)  # type: ignore[arg-type]
    message = str(caught.value)
    assert message.startswith("tasks[0] (move).reference (")
    assert "move.csv) at t = " in message and "joint alpha = " in message
    assert "must lie in [-0.4537, 1.0723] rad, the machine's range [-0.4737, 1.0923] rad less 0.02 rad" in message
    assert "initial_lengths" not in message and "crane" not in message and "\n" not in message
    # the same move with the margin dropped (working_range: reference) is a valid problem
    reference = _study(tmp_path, {**EXCAVATOR_STUDY, "bounds": {**bounds, "working_range": "reference"}})
    assert StudyProblem(reference).n_xi == 9  # type: ignore[arg-type]


def test_a_start_the_inverse_dynamics_refuses_is_called_a_machine_on_a_machine_file(excavator: StudyProblem) -> None:
    error = InvalidInputError("alpha", 1.2, "must lie in [0, 1]", "rad")
    on_machine = str(start_error(error, "initial_lengths", excavator.model))
    assert (
        on_machine
        == "initial_lengths (alpha) = 1.2 rad is out of range: the start is not an admissible machine: "
        + ("must lie in [0, 1]")
    )
    crane = load_study(REPO / "optimize" / "xs031_spiral.yaml").model
    assert "not an admissible crane: " in str(start_error(error, "initial_lengths", crane))


def test_an_out_of_reach_csv_reference_is_named_by_its_task_file_row_and_columns(tmp_path: Path) -> None:
    """The one line the duty-cycle tutorial promises: the task, the file, the row and the columns, said once."""
    rows = [f"{t:.1f},50.0,0.5,-1.0" for t in np.linspace(0.0, 4.0, 41)]
    (tmp_path / "far.csv").write_text("# far away\nt,x,y,tcp_angle\n" + "\n".join(rows) + "\n", encoding="utf-8")
    task = {"name": "move", "weight": 1, "reference": {"kind": "csv", "file": "far.csv"}}
    study = _study(tmp_path, {**EXCAVATOR_STUDY, "tasks": [task]})
    with pytest.raises(InvalidInputError) as caught:
        StudyProblem(study)  # type: ignore[arg-type]
    message = str(caught.value)
    assert message.startswith("tasks[0] (move).reference: ")
    assert "far.csv row 3 (t = 0 s), columns x, y, tcp_angle = 'TCP (50, 0.5) m with tcp_angle = -1 rad'" in message
    assert "out of the machine's reach" in message and "out of range: is out of" not in message


def test_shipped_digging_study_cuts_soil_at_the_tip() -> None:
    """The digging task's TCP force: the soil's resistance while the tip is below ground, the payload's weight after."""
    study = load_study("exact_digging")
    task = study.tasks[0]
    model = study.model
    times = task.times(study.grid.dt)
    force = task.id_force(model.kinematics, model.gravity, times)
    soil = task.soil_force(model.kinematics, model.gravity, times)
    assert force is not None and soil is not None
    ref = task.reference.sample(model.kinematics, times)
    below = ref.position[:, 1] < task.soil.ground - 0.02  # type: ignore[union-attr]
    moving = np.abs(ref.velocity[:, 0]) > 0.03
    assert np.all(np.linalg.norm(soil[below & moving], axis=1) > 100.0)
    assert np.all(soil[ref.position[:, 1] > task.soil.ground] == 0.0)  # type: ignore[union-attr]
    held = (times >= task.payload.pick) & (times < task.payload.release)  # type: ignore[operator]
    weight = force[held & ~below][:, 1] - soil[held & ~below][:, 1]
    # the carried soil: its weight and its inertia at the reference's acceleration (< 0.05 m/s^2 x 76 kg)
    assert np.allclose(weight, -76.0 * model.gravity, atol=76.0 * 0.5)


def _machine_form(text: str) -> str:
    """A crane file's study text turned into the same study of the XS 031's machine file (tracking xt2)."""
    out = []
    for line in text.splitlines():
        key = line.split(":", 1)[0].strip()
        if line.startswith("crane:"):
            out += ["machine: xs031", "tracked: [xt2]"]
        elif (key in ("lift", "tilt") and line.startswith("  ")) or key == "triangle_margin_deg":
            continue  # the machine file declares the bounds; its joint bounds are its ranges
        else:
            out.append(line)
    return "\n".join(out) + "\n"


@pytest.mark.e2e
def test_default_study_on_the_machine_file_reaches_the_crane_files_optimum(tmp_path: Path) -> None:
    """The shipped default study through the XS 031's machine file: the same optimum, iterations and energies.

    Two independent descriptions (the crane file's closed-form chains and analytic ID, the machine
    file's generic tree, tracked kinematics, loop closure and Newton-Euler) and the same NLP otherwise.
    The crane's triangle margin is not a row of the machine file's study; it is inactive at this optimum.
    """
    from hiab_sim.study.run import run_study

    source = REPO / "optimize" / "xs031_spiral.yaml"
    machine_file = tmp_path / "xs031_spiral_machine.yaml"
    machine_file.write_text(_machine_form(source.read_text(encoding="utf-8")), encoding="utf-8")
    crane = run_study(load_study(source), tmp_path / "crane", progress=None, figures=False).result
    machine = run_study(load_study(machine_file), tmp_path / "machine", progress=None, figures=False).result
    a = crane.optimal.lengths.as_array()
    b = machine.optimal.lengths.as_array()
    assert machine.optimal.lengths.names == ("lift.L", "lift.Lc0", "lift.Lc", "tilt.L", "tilt.Lc0", "tilt.Lc")
    assert np.max(np.abs(a - b)) < 1e-8
    assert machine.solver.iterations == crane.solver.iterations
    assert crane.energy is not None and machine.energy is not None
    assert machine.energy.optimal.battery_energy_J == pytest.approx(crane.energy.optimal.battery_energy_J, rel=1e-9)
    assert machine.optimal.net_electrical_energy_J == pytest.approx(crane.optimal.net_electrical_energy_J, rel=1e-9)


def _excavator_with_catalogue(folder: Path, catalogue: dict) -> Path:
    """The small excavator study with ``transmission:`` (its move written next to it)."""
    joint_csv(folder / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump({**EXCAVATOR_STUDY, "transmission": catalogue}), encoding="utf-8")
    return path


def test_a_machine_studys_transmission_catalogue_is_keyed_by_its_actuators(tmp_path: Path) -> None:
    """The catalogue takes the machine file's actuator names; a crane's name there is one line naming them."""
    from hiab_sim.machine.loader import load_machine

    first = load_machine("exact").actuator_names[0]
    study = load_study(_excavator_with_catalogue(tmp_path, {first: [{"gear_ratio": 4.0, "screw_lead": 0.005}]}))
    assert study.energy.transmission is not None
    assert [name for name, _ in study.energy.transmission.options] == [first]
    with pytest.raises(ConfigError, match=rf"transmission: unknown key\(s\) \['lift'\].*{first}"):
        load_study(_excavator_with_catalogue(tmp_path, {"lift": [{"gear_ratio": 4.0, "screw_lead": 0.005}]}))


def test_transmission_keys_are_the_emla_names_where_they_differ_from_the_chain_names(tmp_path: Path) -> None:
    """Chains named apart from their EMLAs: the catalogue takes the EMLA names (the EMLA file's and the result's).

    A chain's name there is one line that lists the EMLA names.
    """
    from importlib import resources

    from hiab_sim.machine.loader import load_machine

    presets = resources.files("hiab_sim") / "presets"
    machine = yaml.safe_load((presets / "exact_excavator.yaml").read_text(encoding="utf-8"))
    emla = yaml.safe_load((presets / "emla_exact.yaml").read_text(encoding="utf-8"))
    chains = load_machine("exact").actuator_names
    for chain in chains:
        machine["chains"][chain]["actuator"]["emla"] = f"e_{chain}"
    emla["actuators"] = {f"e_{chain}": emla["actuators"][chain] for chain in chains}
    (tmp_path / "renamed.yaml").write_text(yaml.safe_dump(machine), encoding="utf-8")
    (tmp_path / "emla.yaml").write_text(yaml.safe_dump(emla), encoding="utf-8")
    joint_csv(tmp_path / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    option = [{"gear_ratio": 4.0, "screw_lead": 0.005}]
    top = {**EXCAVATOR_STUDY, "machine": "renamed.yaml", "emla": "emla.yaml"}
    study = _study(tmp_path, {**top, "transmission": {f"e_{chains[0]}": option}})
    assert [name for name, _ in study.energy.transmission.options] == [f"e_{chains[0]}"]  # type: ignore[attr-defined]
    with pytest.raises(ConfigError, match=rf"transmission: unknown key\(s\) \['{chains[0]}'\].*'e_{chains[0]}'"):
        _study(tmp_path, {**top, "transmission": {chains[0]: option}})


@pytest.mark.e2e
def test_codesign_runs_on_a_machine_file_and_keeps_the_lowest_battery_energy(tmp_path: Path) -> None:
    """Mounting optimised per transmission of one excavator EMLA: the file's own first, the best the cheapest."""
    from hiab_sim.machine.loader import load_machine
    from hiab_sim.study.run import run_study

    first = load_machine("exact").actuator_names[0]
    catalogue = {first: [{"gear_ratio": 3.0, "screw_lead": 0.01}, {"gear_ratio": 5.0, "screw_lead": 0.01}]}
    result = run_study(
        load_study(_excavator_with_catalogue(tmp_path, catalogue)), tmp_path / "run", progress=None, figures=False
    ).result
    codesign = result.codesign
    assert codesign is not None and len(codesign.rows) == 3 and codesign.reference == 0
    assert [r.transmission[first].gear_ratio for r in codesign.rows[1:]] == [3.0, 5.0]
    feasible = [r.battery_energy_J for r in codesign.rows if r.status == "converged" and r.battery_energy_J is not None]
    assert len(feasible) >= 2 and codesign.rows[codesign.best].battery_energy_J == min(feasible)
    assert codesign.codesign_battery_energy_J <= codesign.mounting_only_battery_energy_J

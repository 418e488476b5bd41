"""Energy in the study: battery-energy objective, thermal rows, energy report, co-design and bad input."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import trapezoid
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.errors import InvalidInputError
from hiab_sim.results.energy_sections import TransmissionChoice
from hiab_sim.results.read import read_result
from hiab_sim.study.analysis.codesign import combinations, solve_combination, with_transmission
from hiab_sim.study.constraints.thermal_rows import ThermalLimits
from hiab_sim.study.nlp.task_problem import TaskProblem
from hiab_sim.study.spec.study_file import study_from_dict

FLAGS = ["--no-video", "--quiet", "--no-figures"]


def _study(**changes: object):  # type: ignore[no-untyped-def]
    return study_from_dict(small_study(**changes), "small.yaml")


@pytest.fixture(scope="module")
def energy_problem() -> TaskProblem:
    """The small study with the battery-energy objective, a 60 cycles/hour duty and the paper's EMLA model."""
    return TaskProblem(_study(objective="battery_energy", duty={"cycles_per_hour": 60}, emla="paper"))


def _directions(n: int, count: int = 3) -> list[np.ndarray]:
    rng = np.random.default_rng(13)
    return [d / np.linalg.norm(d) for d in rng.normal(size=(count, n))]


def _exact_battery_energy(time: np.ndarray, power: np.ndarray, eta_inv: float, eta_dis: float, eta_ch: float) -> float:
    """Shared DC bus written out sample by sample (independent of hiab_sim.emla.battery)."""
    bus = np.where(power > 0, power / eta_inv, power * eta_inv).sum(axis=1)
    return float(trapezoid(np.where(bus > 0, bus / eta_dis, bus * eta_ch), time))


def test_battery_objective_gradient_matches_finite_differences_through_the_nlp(
    energy_problem: TaskProblem,
) -> None:
    """d(scaled battery energy)/dz agrees with central differences of the NLP's cost in random directions."""
    p = energy_problem
    z = p.initial_point(p.study.initial_lengths)
    g = p.cost_gradient(z)
    for d in _directions(p.n):
        h = 1e-5
        fd = (p.cost(z + h * d) - p.cost(z - h * d)) / (2 * h)
        assert abs(fd - g @ d) <= 1e-5 * max(1.0, abs(fd)), (fd, g @ d)


def test_smooth_battery_objective_converges_to_the_exact_trapezoid_on_a_fine_grid() -> None:
    """As the softplus width shrinks the NLP's value tends to the exact shared-bus trapezoid, within its bound."""
    study = _study(objective="battery_energy")
    gaps = []
    for eps in (10.0, 1.0, 0.1, 0.01):
        emlas = replace(study.emlas, battery=replace(study.emlas.battery, smoothing_power=eps))
        fine = TaskProblem(study, emlas=emlas, times=study.grid.fine_times(), tightened=False, cost_scale=1.0)
        ev = fine.evaluate(fine.initial_point(study.initial_lengths))
        b = emlas.battery
        exact = _exact_battery_energy(
            ev.joints.time, ev.power, b.inverter_efficiency, b.discharge_efficiency, b.charge_efficiency
        )
        gap = abs(ev.cost - exact)
        assert gap <= b.smoothing_bound(3, study.grid.duration)
        gaps.append(gap)
    assert gaps[-1] < 1e-3 * gaps[0] and gaps[-1] < 1e-4


def test_regeneration_of_one_drive_feeds_another_in_the_nlp_objective(energy_problem: TaskProblem) -> None:
    """Lift drawing 1000 W while tilt returns 400 W: the bus nets them before the battery (hand numbers)."""
    ev = energy_problem.evaluate(energy_problem.initial_point(energy_problem.study.initial_lengths))
    power = np.zeros_like(ev.power)
    power[:, 0], power[:, 1] = 1000.0, -400.0
    state = replace(ev, power=power)
    T = float(ev.joints.time[-1])
    shared = (1000.0 / 0.97 - 400.0 * 0.97) / 0.975 * T  # one bus, then the battery discharges
    separate = (1000.0 / 0.97 / 0.975 - 400.0 * 0.97 * 0.975) * T  # if the regeneration charged the battery
    value = energy_problem.objective.value(state)
    assert energy_problem.objective.name == "battery_energy"
    assert abs(value - shared) <= energy_problem.emlas.battery.smoothing_bound(3, T)
    assert shared < separate - 1.0


def test_thermal_rows_partials_match_finite_differences(energy_problem: TaskProblem) -> None:
    """The RMS-torque and winding-temperature rows' Jacobian agrees with central differences."""
    p = energy_problem
    z = p.initial_point(p.study.initial_lengths)
    rows = p.layout.slices["thermal"]
    jac = p.constraints_jacobian(z)[rows]
    for d in _directions(p.n):
        h = 1e-5
        fd = (p.constraints(z + h * d)[rows] - p.constraints(z - h * d)[rows]) / (2 * h)
        assert np.allclose(fd, jac @ d, rtol=1e-4, atol=1e-7), (fd, jac @ d)


def test_thermal_rows_exist_only_with_a_duty_and_hold_at_60_cycles_per_hour_not_back_to_back() -> None:
    """No duty, no rows; the start meets both limits at 60 cycles/hour and breaks the lift's RMS limit without rest."""
    assert "thermal" not in TaskProblem(_study()).layout.slices
    busy = TaskProblem(_study(duty={"cycles_per_hour": 60}))
    assert any(isinstance(block, ThermalLimits) for block in busy.layout.blocks)
    z = busy.initial_point(busy.study.initial_lengths)
    assert busy.margins(z)[busy.layout.slices["thermal"]].min() > 0.0
    nonstop = TaskProblem(_study(duty={"rest_time": 0.0}))
    values = nonstop.layout.split(nonstop.margins(z))["thermal"]
    assert values[0] < 0.0  # lift rms torque above the continuous torque


@pytest.mark.e2e
def test_every_result_reports_both_objectives_battery_thermal_and_hydraulics(tmp_path: Path) -> None:
    """result.json has the energy and hydraulic sections; costf2 and the battery energy match independent sums."""
    study = write_study(tmp_path, small_study(duty={"cycles_per_hour": 60}, emla="paper"))
    assert main(["optimize", str(study), "--out", str(tmp_path / "out"), *FLAGS]) == 0
    r = read_result(tmp_path / "out")
    assert r.energy is not None and r.hydraulic_baseline is not None
    assert r.energy.objective == "costf2" and r.optimal.cost_W2s == pytest.approx(r.energy.optimal.costf2_W2s)
    data = np.load(tmp_path / "out" / "trajectory.npz")
    t, p = data["time"], data["optimal_electrical_power"]
    assert r.energy.optimal.battery_energy_J == pytest.approx(_exact_battery_energy(t, p, 0.97, 0.975, 0.975), 1e-12)
    drawn = [float(trapezoid(np.maximum(p[:, i], 0.0), t)) for i in range(3)]
    assert list(r.energy.optimal.drawn_energy_J.values()) == pytest.approx(drawn, rel=1e-12)
    assert (
        r.energy.optimal.thermal is not None and min(th.torque_margin for th in r.energy.optimal.thermal.values()) > 0
    )
    for design in (r.hydraulic_baseline.initial, r.hydraulic_baseline.optimal):
        assert design.load_sensing.input_energy_J < design.constant_pressure.input_energy_J
    assert (tmp_path / "out" / "result.json").read_text().count('"hydraulic_baseline"') == 1


def test_codesign_combinations_start_with_the_file_transmission_and_change_k() -> None:
    """Row 0 is the EMLA file's (G, rho); duplicates are dropped; the replaced set has k = 2 pi G / rho."""
    study = _study(
        transmission={"lift": [{"gear_ratio": 4.0, "screw_lead": 0.01}, {"gear_ratio": 5.0, "screw_lead": 0.01}]}
    )
    combos = combinations(study)
    assert len(combos) == 2 and combos[0]["lift"] == TransmissionChoice(4.0, 0.01)
    emlas = with_transmission(study.emlas, combos[1])
    assert emlas.lift.transmission_ratio == pytest.approx(2 * np.pi * 5.0 / 0.01)
    assert emlas.tilt == study.emlas.tilt


def test_codesign_lists_a_transmission_too_fast_for_the_motor_as_an_infeasible_start() -> None:
    """A tilt gear ratio of 8 needs more than the rated motor speed: the row says so, naming the constraint."""
    study = _study(transmission={"tilt": [{"gear_ratio": 8.0, "screw_lead": 0.01}]})
    row = solve_combination(study, combinations(study)[1])
    assert row.status == "infeasible start" and "envelope" in row.message and row.battery_energy_J is None


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"objective": "energy"}, "objective = 'energy'"),
        ({"duty": {}}, "duty = "),
        ({"duty": {"cycles_per_hour": 0}}, "duty.cycles_per_hour"),
        ({"duty": {"cycles_per_hour": 1000}}, "duty.cycles_per_hour = 1000"),
        ({"duty": {"rest_time": -1.0}}, "duty.rest_time"),
        ({"transmission": {}}, "transmission = "),
        ({"transmission": {"lift": []}}, "transmission.lift = "),
        ({"transmission": {"lift": [{"gear_ratio": 1.0, "screw_lead": 0.01}]}}, "transmission.lift[0].gear_ratio"),
    ],
)
def test_bad_energy_settings_exit_2_naming_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], change: dict, field: str
) -> None:
    """Unknown objective, a duty with no time, an empty catalogue, G <= 1: named field, exit 2, nothing written."""
    study = write_study(tmp_path, small_study(**change))
    out = tmp_path / "out"
    assert main(["optimize", str(study), "--out", str(out), *FLAGS]) == 2
    err = capsys.readouterr().err
    assert field in err and "Traceback" not in err
    assert not out.exists()


def test_negative_thermal_resistance_in_the_emla_file_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An EMLA file with a negative thermal resistance is refused with its field named."""
    from hiab_sim.resources import locate

    text = locate("default", "emla").read_bytes().decode()
    emla = tmp_path / "emla.yaml"
    emla.write_text(text.replace("value: 0.4665", "value: -0.4665"))
    study = write_study(tmp_path, small_study(emla=str(emla)))
    assert main(["optimize", str(study), "--out", str(tmp_path / "out"), *FLAGS]) == 2
    assert "thermal.thermal_resistance = -0.4665" in capsys.readouterr().err
    with pytest.raises(InvalidInputError, match="thermal_resistance"):
        study_from_dict(small_study(emla=str(emla)), tmp_path / "s.yaml")


def _losses_on(tmp_path: Path) -> Path:
    """The paper's EMLA file with ``drive_losses`` enabled and the battery's inverter efficiency 1."""
    from hiab_sim.resources import locate

    text = locate("paper", "emla").read_bytes().decode()
    text = text.replace("drive_losses:\n  enabled: false", "drive_losses:\n  enabled: true")
    text = text.replace("value: 0.97\n", "value: 1.0\n", 1)
    path = tmp_path / "emla_losses.yaml"
    path.write_text(text)
    return path


def test_drive_losses_enabled_in_the_emla_file_flow_into_the_objective_and_the_report(tmp_path: Path) -> None:
    """Losses on: the NLP's battery energy rises, its gradient still matches differences, the report names them."""
    from hiab_sim.study.report.energy_section import design_energy

    study_on = _study(objective="battery_energy", emla=str(_losses_on(tmp_path)))
    study_off = _study(objective="battery_energy", emla="paper")
    assert study_on.emlas.lift.losses.inverter_on and study_on.emlas.battery.inverter_efficiency == 1.0
    on, off = (TaskProblem(s, cost_scale=1.0) for s in (study_on, study_off))
    z = on.initial_point(study_on.initial_lengths)
    assert on.cost(z) > off.cost(z)
    g = on.cost_gradient(z)
    for d in _directions(on.n, 2):
        h = 1e-5
        fd = (on.cost(z + h * d) - on.cost(z - h * d)) / (2 * h)
        assert abs(fd - g @ d) <= 1e-5 * max(1.0, abs(fd))
    fine = TaskProblem(study_on, times=study_on.grid.fine_times(), tightened=False, cost_scale=1.0)
    e = design_energy(fine, fine.evaluate(z))
    assert e.drive_loss_energy_J is not None
    assert e.drive_loss_energy_J["lift"]["transmission_loss"] > 0 and e.drive_loss_energy_J["lift"]["inverter_loss"] > 0
    assert abs(e.battery_energy_J - e.battery_energy_smooth_J) < 0.01 * e.battery_energy_J
    # smooth - exact = the battery kinks' smoothing (within its bound) + the drive losses' smoothing (reported)
    assert e.drive_loss_smoothing_J is not None
    kinks = e.battery_energy_smooth_J - e.drive_loss_smoothing_J - e.battery_energy_J
    assert 0.0 <= kinks <= e.smoothing_bound_J
    assert (
        design_energy(
            TaskProblem(study_off, times=study_off.grid.fine_times(), tightened=False, cost_scale=1.0),
            fine.evaluate(z),
        ).drive_loss_energy_J
        is None
    )


@given(cycle=st.floats(0.5, 600.0), fraction=st.floats(1e-3, 1.0))
def test_cycles_per_hour_give_a_duty_period_of_3600_over_n(cycle: float, fraction: float) -> None:
    """N cycles an hour of a T-second cycle: rest 3600/n - T >= 0 and period 3600/n [s]."""
    from hiab_sim.study.spec.energy import DutySettings

    n = fraction * 3600.0 / cycle
    duty = DutySettings(cycles_per_hour=n).duty(cycle)
    assert duty.rest_time >= 0.0
    assert duty.period == pytest.approx(max(3600.0 / n, cycle), rel=1e-12)

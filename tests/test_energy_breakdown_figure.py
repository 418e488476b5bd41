"""The energy-breakdown figure's bars: the parts and the drive train's add up to the electrical energy."""

from __future__ import annotations

import pytest
from test_study_small import small_study

from hiab_sim.study.figures.optimisation import drive_train_energy
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.report.design_check import design_summary, fine_problem
from hiab_sim.study.spec.study_file import study_from_dict


@pytest.mark.parametrize("emla", ["default", "paper"])
def test_the_bars_balance_the_electrical_energy(emla: str) -> None:
    """Mechanical work, motor losses and drive train add up to the electrical energy, real drive and paper drive.

    The breakdown's parts come from the design summary (``result.json``'s ``energy_breakdown_J``), the
    drive train's bar from the EMLA file's loss terms; the electrical energy is the drive model's own
    P_elec, so the sum checks that the bars leave nothing out. On the paper's drive the drive train is 0.
    """
    data = small_study() if emla == "default" else small_study(emla="paper")
    problem = StudyProblem(study_from_dict(data, "small.yaml"))
    fine = fine_problem(problem.problems[0])
    check = design_summary(fine, problem.initial_point(problem.study.initial_lengths))
    parts = check.summary.energy_breakdown_J
    drive = drive_train_energy(fine.emlas, check, fine.times)
    motor = parts.mechanical + parts.copper + parts.rotor_friction + parts.screw_viscous + parts.inertial
    assert motor + drive == pytest.approx(parts.electrical, rel=1e-9, abs=1e-6)
    if emla == "paper":
        assert drive == 0.0
    else:
        assert drive > 0.1 * parts.electrical  # the real drive's screw, gear and inverter: a large share

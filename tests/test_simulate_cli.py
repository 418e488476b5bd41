"""``hiab-sim simulate``: closed-loop validation of an optimisation result, its files and its bad input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.study.run import run_study

#: End-to-end runs of whole studies and commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def small_result(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small study optimised once (analytic ID path, no figures), on the paper's EMLA model.

    The closed loop's time-domain drives model the paper's drive (no transmission or inverter loss),
    so its energy is compared with a prediction of the same model.
    """
    folder = tmp_path_factory.mktemp("small_closed_loop")
    study = write_study(folder, small_study(emla="paper"))
    return run_study(study, folder / "out", progress=None, figures=False).folder


def test_simulate_writes_the_validation_of_one_design(
    small_result: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """simulation.json holds closed-loop and predicted energies (drives and battery), TCP errors, limits, bandwidth.

    The check's lowest natural frequency is the study's own (``result.json``'s structure section,
    computed by the optimiser on the same fine grid), the margin is 1 - f_v / (f_1 / 3) of the
    controller's velocity loop and it holds; the closing summary prints it.
    """
    out = tmp_path / "sim"
    assert main(["simulate", str(small_result), "--design", "optimal", "--no-video", "--quiet", "--out", str(out)]) == 0
    report = json.loads((out / "simulation.json").read_text())
    entry = report["designs"]["optimal"]
    result = json.loads((small_result / "result.json").read_text())
    predicted = result["optimal"]["net_electrical_energy_J"]
    check = entry["bandwidth_check"]
    f_v, f_1 = check["velocity_loop_bandwidth_Hz"], check["first_natural_frequency_Hz"]
    assert f_1 == pytest.approx(result["structure"]["optimal"]["lowest_frequency_trajectory_Hz"], rel=1e-9)
    assert f_v == pytest.approx(report["settings"]["cascade_bandwidths_rad_per_s"]["velocity"] / (2 * math.pi))
    assert check["bandwidth_margin"] == pytest.approx(1.0 - f_v / (f_1 / 3.0)) and check["bandwidth_margin"] >= 0.0
    printed = capsys.readouterr().out
    assert f"velocity loop {f_v:.2f} Hz" in printed and "bandwidth_margin" in printed and "holds" in printed
    assert entry["predicted_net_electrical_energy_J"] == predicted
    assert entry["net_electrical_energy_J"] == pytest.approx(predicted, rel=0.02)
    assert entry["tcp_error_mm"]["rms"] <= 2.0 and entry["tcp_error_mm"]["max"] <= 5.0
    assert entry["current_limit_fraction"] == 0.0 and entry["voltage_limit_fraction"] == 0.0
    # the battery's boundary: the planner's cycle battery energy and the closed loop's through the same battery
    assert entry["predicted_battery_energy_J"] == result["energy"]["optimal"]["battery_energy_J"]
    assert entry["battery_energy_J"] == pytest.approx(entry["predicted_battery_energy_J"], rel=0.02)
    assert sorted(p.name for p in out.glob("closed_loop_*.png")) == [
        "closed_loop_drives.png",
        "closed_loop_energy.png",
        "closed_loop_power.png",
        "closed_loop_tcp_error.png",
    ]
    assert not list(out.glob(".*part*"))  # atomic writes leave no temporary files
    assert "energy_boundary" not in report  # the paper's model: the plan and the closed loop count the same


def test_with_the_real_drive_the_closed_loop_still_follows_its_plan(tmp_path: Path) -> None:
    """The feedforward leaves the planner's transmission losses out: the closed loop follows its plan.

    The EMLA file's screw and gearbox losses are the planner's, not the simulated drive's; with them in
    the feedforward the 2.35 Hz velocity loop let the default study's TCP drift 15.6 mm from the plan.
    """
    study = write_study(tmp_path, small_study(emla="default"))
    result = run_study(study, tmp_path / "out", progress=None, figures=False).folder
    out = tmp_path / "sim"
    assert main(["simulate", str(result), "--design", "optimal", "--no-video", "--quiet", "--out", str(out)]) == 0
    entry = json.loads((out / "simulation.json").read_text())["designs"]["optimal"]
    assert entry["tcp_error_to_plan_mm"]["max"] <= 0.5


def test_the_energy_boundary_names_the_drive_losses_the_closed_loop_does_not_model() -> None:
    """The default EMLA file's drive losses are named (every drive); the paper's lossless file needs no note."""
    from hiab_sim.emla.config import load_emla_set
    from hiab_sim.env.validation import energy_boundary

    note = energy_boundary(load_emla_set("default"))
    assert note is not None and "transmission eta" in note and "(lift, tilt, telescope)" in note
    assert energy_boundary(load_emla_set("paper")) is None


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        (["--payload-error", "-0.5"], "--payload-error"),
        (["--payload-error", "nan"], "--payload-error"),
    ],
)
def test_bad_input_exits_2_with_one_line(
    small_result: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], field: str
) -> None:
    """Out-of-range values exit 2 with one line naming the field, and write nothing."""
    out = tmp_path / "sim"
    assert main(["simulate", str(small_result), "--no-video", "--quiet", "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0] and "Traceback" not in err[0]
    assert not out.exists()


def test_a_result_whose_study_file_is_gone_exits_2(
    small_result: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The study file names the plan's EMLA set and duty (here the paper's drive): gone, simulate refuses.

    One line naming the file and what it is needed for; without it the closed loop ran on the preset
    EMLA set and compared another drive with the plan.
    """
    import json
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(small_result, copy)
    data = json.loads((copy / "result.json").read_text(encoding="utf-8"))
    data["study"] = str(tmp_path / "gone.yaml")
    (copy / "result.json").write_text(json.dumps(data), encoding="utf-8")
    out = tmp_path / "sim"
    assert main(["simulate", str(copy), "--no-video", "--quiet", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "gone.yaml" in err[0] and "EMLA set" in err[0] and not out.exists()


def test_a_folder_without_a_result_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """RESULT_DIR without result.json: a one-line error naming the folder and the missing file, exit 2."""
    assert main(["simulate", str(tmp_path), "--no-video", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(tmp_path) in err[0] and "result.json" in err[0]


@pytest.mark.sim
def test_default_study_validates_in_closed_loop(tmp_path: Path) -> None:
    """The closed-loop claims on the default study's lossless variant, both designs, end mass 20 % heavier.

    Energy within 2 % of the prediction, TCP error rms <= 2 mm and max <= 5 mm, the optimal design
    cheaper than the initial one in closed loop too; with +20 % end mass the cycle completes within
    20 mm and the extra energy is reported.
    """
    # the default study with the paper's lossless drive (seed_faithful): the closed loop's drives model
    # no transmission, inverter or brake losses, so the 2 % claim compares like with like
    study = Path(__file__).resolve().parents[1] / "optimize" / "seed_faithful.yaml"
    result = run_study(study, tmp_path / "run", progress=None, figures=False).folder
    assert main(["simulate", str(result), "--no-video", "--quiet", "--payload-error", "0.2"]) == 0
    report = json.loads((result / "simulation.json").read_text())
    designs = report["designs"]
    for design in ("initial", "optimal"):
        nominal, heavy = designs[design]["nominal"], designs[design]
        assert nominal["net_electrical_energy_J"] == pytest.approx(
            nominal["predicted_net_electrical_energy_J"], rel=0.02
        )
        assert nominal["tcp_error_mm"]["rms"] <= 2.0 and nominal["tcp_error_mm"]["max"] <= 5.0
        assert heavy["tcp_error_mm"]["max"] <= 20.0 and heavy["simulated_time_s"] == pytest.approx(6.25)
        assert heavy["extra_energy_J"] > 0.0
    assert (
        designs["optimal"]["nominal"]["net_electrical_energy_J"]
        < designs["initial"]["nominal"]["net_electrical_energy_J"]
    )


def test_simulate_on_the_realistic_plant_reports_every_effect(small_result: Path, tmp_path: Path) -> None:
    """--plant realistic: plant_effects holds ideal, each effect alone and all, both designs, shares, the mass split."""
    out = tmp_path / "sim"
    args = ["simulate", str(small_result), "--plant", "realistic", "--no-video", "--quiet", "--out", str(out)]
    assert main(args) == 0
    report = json.loads((out / "simulation.json").read_text())
    effects = report["plant_effects"]
    assert list(effects["variants"]) == ["ideal", *effects["effects_on"], "all"]
    for entry in effects["variants"].values():
        for design in ("initial", "optimal"):
            assert entry[design]["tcp_error_mm"]["max"] <= 10.0
        assert isinstance(entry["optimal_below_initial"], bool)
    ideal = effects["variants"]["ideal"]["optimal"]
    assert ideal["dc_bus_energy_J"] == pytest.approx(ideal["predicted_net_electrical_energy_J"], rel=0.02)
    split = effects["mismatch_split"]["optimal"]
    assert split["predicted_at_true_masses_J"] > split["predicted_J"]
    # No worse than the nominal optimum at the true masses, within the small study's solver and ID tolerances.
    assert split["replanned_optimum_predicted_J"] <= split["predicted_at_true_masses_J"] * (1 + 1e-3)
    assert (out / "closed_loop_plant_effects.png").is_file()
    compact = (out / "effects.md").read_text(encoding="utf-8").split("\n\n")[1].splitlines()
    assert compact[0] == "| effect | " + " | ".join(effects["variants"]) + " |"
    tcp = effects["variants"]["all"]["optimal"]["tcp_error_mm"]["max"]
    assert compact[3].endswith(f"/ {tcp:.2f} |")


def test_a_bad_plant_exits_2_naming_it(small_result: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An unknown plant name or a zero cycle count exits 2 with one line, nothing written."""
    out = tmp_path / "sim"
    for extra, word in ((["--plant", "windy"], "windy"), (["--cycles", "0"], "--cycles")):
        assert main(["simulate", str(small_result), "--no-video", "--quiet", "--out", str(out), *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and word in err[0]
        assert not out.exists()


@pytest.mark.slow
def test_default_study_on_the_realistic_plant(tmp_path: Path) -> None:
    """The default study's both designs complete on the realistic plant within 10 mm, over two cycles.

    The ideal plant (the EMLA file's real drive, the planner's losses) draws the planner's energy of the
    plan on a 5 ms grid within 0.06 %, and the optimiser's number (25 ms grid) within 0.06 % too: the
    brake closes only for the rest, so no release inside the cycle separates the two grids (measured
    -0.03 % / -0.04 % on the initial design, -0.03 % / -0.03 % on the optimal one).
    """
    result = run_study(None, tmp_path / "run", progress=None, figures=False).folder
    args = ["simulate", str(result), "--plant", "realistic", "--cycles", "2", "--no-video", "--no-figures", "--quiet"]
    assert main(args) == 0
    effects = json.loads((result / "simulation.json").read_text())["plant_effects"]
    for design in ("initial", "optimal"):
        ideal = effects["variants"]["ideal"][design]
        assert ideal["dc_bus_energy_J"] == pytest.approx(ideal["predicted_net_electrical_energy_5ms_grid_J"], rel=6e-4)
        assert ideal["dc_bus_energy_J"] == pytest.approx(ideal["predicted_net_electrical_energy_J"], rel=6e-4)
        every = effects["variants"]["all"][design]
        assert every["tcp_error_mm"]["max"] <= 10.0
        temperatures = [c["winding_temperature_C"][0] for c in every["cycles"]]
        assert temperatures[1] > temperatures[0]
    assert "optimal_below_initial" in effects["variants"]["all"]

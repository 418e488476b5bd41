"""hiab-sim report: one self-contained HTML file that states the answer, opened in a real browser."""

from __future__ import annotations

import functools
import http.server
import json
import re
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from browser_helper import References, chromium, load_page, save_artifact
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.design_report.page import esc
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import Result, TaskResult

#: End-to-end runs of whole commands (optimize, report, Chromium, tutorials): not in the fast tier.
pytestmark = pytest.mark.e2e

ROOT = Path(__file__).resolve().parents[1]
needs_chromium = pytest.mark.skipif(
    chromium() is None, reason="chromium is not installed (scripts/setup.sh installs it)"
)


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small study optimised by the CLI with its figures (no video): optimize writes report.html by default."""
    folder = tmp_path_factory.mktemp("report")
    study = write_study(folder, small_study(duty={"cycles_per_hour": 60}))
    assert main(["optimize", str(study), "--out", str(folder / "run"), "--no-video", "--quiet"]) == 0
    return folder / "run"


@pytest.fixture(scope="module")
def result(run_dir: Path) -> Result:
    """The run's result."""
    return read_result(run_dir)


def test_optimize_writes_a_report_with_no_external_reference(run_dir: Path) -> None:
    """report.html loads nothing from outside itself: no script, link or frame; every src a data: URI."""
    parser = References()
    parser.feed((run_dir / "report.html").read_text())
    assert parser.tags == []
    assert parser.urls and all(url.startswith("data:image/png;base64,") for url in parser.urls)
    assert not any("url(" in style or "@import" in style for style in parser.styles)


def test_report_states_the_design_to_build_and_its_energies(run_dir: Path, result: Result) -> None:
    """The buildable lengths, the battery and net energies and the hydraulic baseline of result.json are in the page."""
    html = (run_dir / "report.html").read_text()
    assert result.buildable is not None and result.energy is not None and result.hydraulic_baseline is not None
    lift = result.buildable.lengths.lift
    assert f"lift L / Lc0 / Lc = {lift.L:.3f} / {lift.Lc0:.3f} / {lift.Lc:.3f} m" in html
    assert f"{result.energy.optimal.battery_energy_J:.1f} J" in html
    assert f"{result.optimal.net_electrical_energy_J:.1f} J" in html
    assert f"{result.hydraulic_baseline.optimal.load_sensing.input_energy_J / 1e3:.1f} kJ" in html
    for title in ("The question", "Thermal state", "Sensitivities", "Hydraulic comparison", "Provenance"):
        assert f"<h2>{title}</h2>" in html
    assert "Closed-loop validation" not in html  # no simulation.json yet


def test_report_gives_the_rounded_designs_net_energy_in_its_own_row(run_dir: Path, result: Result) -> None:
    """The answer builds the rounded design: the energy column is headed "optimum", the rounded design has its row."""
    html = (run_dir / "report.html").read_text()
    assert result.buildable is not None
    section = html.split("<h2>Energies and their boundaries</h2>")[1].split("<h2>")[0]
    cells = [re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", row) for row in re.findall(r"<tr>(.*?)</tr>", section)]
    assert cells[0][2:] == ["initial", "optimum", "change"]
    net = next(row for row in cells if row[0] == "net electrical energy")
    rounded = next(row for row in cells if row[0] == "net electrical energy of the rounded design to build")
    assert net[3] == f"{result.optimal.net_electrical_energy_J:.1f} J"
    assert rounded[3] == f"{result.buildable.net_electrical_energy_J:.1f} J"
    assert rounded[2] == net[2] == f"{result.initial.net_electrical_energy_J:.1f} J"
    assert result.buildable.recheck_id_path in rounded[1]


def test_report_shows_the_closed_loop_of_simulation_json(run_dir: Path, tmp_path: Path) -> None:
    """With a simulation.json in the folder the report has its closed-loop section with the file's numbers."""
    design = {
        "payload_error": 0.0,
        "predicted_net_electrical_energy_J": 3978.4,
        "net_electrical_energy_J": 3976.0,
        "energy_difference_percent": -0.06,
        "tcp_error_mm": {"rms": 0.63, "max": 0.83},
        "current_limit_fraction": 0.0,
        "voltage_limit_fraction": 0.0,
    }
    (run_dir / "simulation.json").write_text(json.dumps({"designs": {"optimal": design}}))
    try:
        out = tmp_path / "with_sim.html"
        assert main(["report", str(run_dir), "-o", str(out)]) == 0
        html = out.read_text()
    finally:
        (run_dir / "simulation.json").unlink()
    assert "<h2>Closed-loop validation</h2>" in html and '<td class="num">3976.0</td>' in html and "-0.06 %" in html


def test_report_of_a_folder_without_a_result_exits_2_and_writes_nothing(tmp_path: Path) -> None:
    """A missing result is one line on stderr, exit status 2, and no report file."""
    done = subprocess.run(
        [sys.executable, "-m", "hiab_sim", "report", str(tmp_path / "nothing"), "-o", str(tmp_path / "r.html")],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2 and "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "r.html").exists()


@needs_chromium
def test_report_renders_in_chromium(run_dir: Path, result: Result) -> None:
    """Headless Chromium: no console error, every image decoded, no request leaves the file, the answer in the text."""
    page = load_page((run_dir / "report.html").as_uri())
    save_artifact("report.png", page.screenshot)
    assert page.errors == []
    assert len(page.images) >= 4 and all(i["complete"] and i["width"] > 0 for i in page.images)
    assert all(url.startswith(("file:", "data:")) for url in page.requests)
    assert result.buildable is not None and result.energy is not None
    assert f"{result.buildable.lengths.tilt.L:.3f}" in page.text
    assert f"{result.energy.optimal.battery_energy_J:.1f} J" in page.text


@needs_chromium
def test_report_prints_to_pdf(run_dir: Path, tmp_path: Path) -> None:
    """--pdf writes a PDF of the same page next to the HTML file."""
    out = tmp_path / "design.html"
    assert main(["report", str(run_dir), "-o", str(out), "--pdf"]) == 0
    assert out.with_suffix(".pdf").read_bytes().startswith(b"%PDF")


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """The built documentation site (site/ from scripts/test.sh, else built here), served on localhost."""
    folder = ROOT / "site"
    if not (folder / "index.html").is_file():
        folder = tmp_path_factory.mktemp("site")
        build = [sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "--site-dir", str(folder)]
        subprocess.run(build, cwd=ROOT, check=True, capture_output=True)
    handler = functools.partial(_QuietHandler, directory=str(folder))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_port}"
    server.shutdown()


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:
        """Keep the test output clean."""


@needs_chromium
def test_documentation_page_renders_in_chromium(site: str) -> None:
    """The default-study page: no console error, images decoded, nothing fetched off the host, its numbers shown."""
    page = load_page(f"{site}/results/default-study/")
    save_artifact("site_default_study.png", page.screenshot)
    assert page.errors == []
    assert page.images and all(i["complete"] and i["width"] > 0 for i in page.images)
    assert all(url.startswith((site, "data:")) for url in page.requests)
    block = (
        (ROOT / "docs" / "results" / "default-study.md").read_text().split("<!-- results:default-study:start -->")[1]
    )
    battery = next(line for line in block.splitlines() if line.startswith("| battery energy"))
    assert battery.split("|")[2].strip().split(" J")[0] in page.text


def _as_task(result: Result, name: str, weight: float, with_energy: bool = True) -> TaskResult:
    """The small study's result as one task of a made-up duty mix (its designs, re-check and energies)."""
    return TaskResult(
        name=name,
        weight=weight,
        kind="spiral",
        duration_s=6.25,
        payload_kg=150.0,
        telescope="prescribed",
        spline_control_points=16,
        collocation_points=13,
        initial=result.initial,
        optimal=result.optimal,
        recheck=result.recheck,
        energy=result.energy if with_energy else None,
    )


def test_report_of_a_duty_mix_shows_its_tasks_and_cross_evaluation(
    run_dir: Path, result: Result, tmp_path: Path
) -> None:
    """A result with tasks and a cross-evaluation gets the duty-mix section with each task and each design's cells."""
    import shutil
    from dataclasses import replace

    from hiab_sim.results.analysis_sections import CrossEvaluation

    task = _as_task(result, "lifting", 20.0, with_energy=False)
    cross = CrossEvaluation(
        note="test",
        tasks=("lifting",),
        weights=(20.0,),
        designs=("lifting alone", "mix"),
        lengths=(result.optimal.lengths, result.optimal.lengths),
        net_energy_J=((1234.5,), (None,)),
        drawn_energy_J=((1300.0,), (None,)),
        cost_W2s=((1.0,), (None,)),
        max_violation=((0.0,), (None,)),
        mix_net_energy_J=(24690.0, None),
        mix_cost_W2s=(20.0, None),
        mix_energy_lost_J=(0.0, None),
        mix_energy_lost_percent=(0.125, None),
        mix_cost_lost_percent=(0.0, None),
    )
    folder = tmp_path / "mix"
    shutil.copytree(run_dir, folder)
    mixed = replace(result, tasks=(task,), cross_evaluation=cross)
    (folder / "result.json").write_text(json.dumps(mixed.to_json()))
    assert main(["report", str(folder)]) == 0
    html = (folder / "report.html").read_text()
    assert "<h2>Duty mix</h2>" in html and "lifting x 20" in html
    assert "1234.5" in html and "24690.0" in html and "+0.125 %" in html and "–" in html  # a missing cell: en dash


def _answer_box(html: str) -> str:
    """The text of the page's answer box (the first ``<div class="answer">``)."""
    start = html.index('<div class="answer">')
    return html[start : html.index("</div>", start)]


def test_report_names_the_period_its_battery_energy_covers(run_dir: Path, result: Result) -> None:
    """With a duty the battery energy covers cycle and rest: named so (as summary.md does), the cycle beside it."""
    html = (run_dir / "report.html").read_text()
    assert result.energy is not None and result.energy.optimal.duty is not None
    assert "battery energy per cycle" not in html
    assert "battery energy per duty period (cycle and rest)" in html
    assert f"{result.energy.optimal.duty.cycle_battery_energy_J:.1f} J" in html


def test_report_answer_states_the_saving_the_binding_limits_and_the_check(run_dir: Path, result: Result) -> None:
    """The answer box says what the summary's answer says: battery energy before/after, binding limits, re-check."""
    import html as html_lib

    from hiab_sim.study.report.summary import binding_line, check_line, energy_line

    box = html_lib.unescape(_answer_box((run_dir / "report.html").read_text()))
    for line in (energy_line(result), binding_line(result), check_line(result)):
        assert line in box
    assert line in (run_dir / "summary.md").read_text()


def test_binding_limits_name_the_objective_they_are_gains_of(result: Result) -> None:
    """The multipliers are gains in the study's objective: costf2 is a squared power, not called an energy gain."""
    from hiab_sim.study.report.summary import binding_line

    assert result.sensitivity is not None and result.sensitivity.multipliers
    line = binding_line(result)
    if result.sensitivity.objective == "battery_energy":
        assert "largest energy gain" in line
    else:
        assert "energy gain" not in line and f"gain in {result.sensitivity.objective}" in line


def test_report_saving_decomposition_adds_up_to_the_saving(run_dir: Path, result: Result) -> None:
    """Lengths, trajectory and their interaction add up to the net energy saved, and all three are on the page."""
    d = result.improvement.decomposition
    assert d.from_lengths_J is not None and d.from_trajectory_J is not None and d.interaction_J is not None
    html = (run_dir / "report.html").read_text()
    assert f"Of the {result.improvement.net_energy_saved_J:.1f} J net energy saved" in html
    assert f"{d.interaction_J:+.1f} J from their interaction" in html


def test_report_compares_hydraulics_at_one_boundary_over_one_period(run_dir: Path, result: Result) -> None:
    """EMLA and cylinders both at the battery over the cycle; no result.json key names shown to the reader."""
    h = result.hydraulic_baseline
    assert h is not None and h.optimal.at_battery and h.optimal.emla_cycle_battery_energy_J is not None
    html = (run_dir / "report.html").read_text()
    hydraulic = html[html.index("<h2>Hydraulic comparison</h2>") :]
    hydraulic = hydraulic[: hydraulic.index("</section>")]
    assert f"{h.optimal.emla_cycle_battery_energy_J / 1e3:.2f} kJ" in hydraulic
    for variant in h.optimal.at_battery.values():
        assert f"{variant.cycle_battery_energy_J / 1e3:.2f} kJ ({variant.emla_saving_percent:.1f} %)" in hydraulic
    # the duty period's battery energy (rest included) is not set against the cylinders' cycle
    assert f"{h.optimal.emla_saving_vs_load_sensing_percent:.1f} %" not in hydraulic
    assert "at_battery" not in hydraulic and "load_sensing" not in hydraulic


def test_hydraulic_figure_draws_the_emlas_cycle_energy(
    run_dir: Path, result: Result, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The figure's EMLA bar, like the cylinders' bars, covers the cycle alone (not the duty period's rest)."""
    from hiab_sim.study.figures import energy

    drawn: list[float] = []

    def capture(names: object, emla_drawn: object, battery_energy: float, *rest: object) -> None:
        drawn.append(battery_energy)
        raise RuntimeError("captured")

    monkeypatch.setattr(energy, "plot_energy_comparison", capture)
    with pytest.raises(RuntimeError, match="captured"):
        energy.hydraulic_figure(run_dir / "unused.png", result)
    assert result.hydraulic_baseline is not None
    assert drawn == [result.hydraulic_baseline.optimal.emla_cycle_battery_energy_J]


def test_report_sensitivity_names_its_grid_and_units_have_one_space(run_dir: Path) -> None:
    """The objective value of the multipliers is the collocation grid's (not the energies' fine grid); '7.83 Hz'."""
    html = (run_dir / "report.html").read_text()
    assert "at the optimum on the optimiser&#x27;s collocation grid" in html
    assert "  Hz" not in html and " Hz</td>" in html


def test_report_says_a_screw_in_tension_throughout_never_pushes(run_dir: Path, result: Result) -> None:
    """A negative largest n f / P_cr (the screw only pulls) is labelled, not left as a bare negative utilisation."""
    assert result.structure is not None
    html = (run_dir / "report.html").read_text()
    pulled = [b for b in result.structure.optimal.buckling.values() if b.peak_push_N <= 0.0]
    assert pulled, "the small study's telescope screw only pulls"
    for b in pulled:
        assert f"{b.max_utilisation:.3f} (tension only, never pushed)" in html


def test_report_of_a_duty_mix_names_its_weighted_sums_and_each_tasks_battery_energy(
    run_dir: Path, result: Result, tmp_path: Path
) -> None:
    """A mix's top-level energies are weighted sums (J/h for cycles/h), not per cycle; each task's too."""
    import shutil
    from dataclasses import replace

    assert result.energy is not None
    task = _as_task(result, "lifting", 20.0)
    folder = tmp_path / "mix"
    shutil.copytree(run_dir, folder)
    (folder / "result.json").write_text(json.dumps(replace(result, tasks=(task,)).to_json()))
    assert main(["report", str(folder)]) == 0
    html = (folder / "report.html").read_text()
    assert "battery energy per cycle" not in html and "battery energy per duty period" not in html
    assert "battery energy, the tasks&#x27; weighted sum" in html and "lifting x 20" in html
    assert "net energy, the tasks&#x27; weighted sum" in html
    e = result.energy
    assert f"{e.initial.battery_energy_J:.1f} → {e.optimal.battery_energy_J:.1f} J (per duty period)" in html


def test_report_of_a_duty_mix_gives_each_tasks_thermal_state(run_dir: Path, result: Result, tmp_path: Path) -> None:
    """A mix's thermal state is per task (its own cycle and duty): a row per task and motor, none left out."""
    import shutil
    from dataclasses import replace

    assert result.energy is not None and result.energy.optimal.thermal is not None
    tasks = (_as_task(result, "lifting", 20.0), _as_task(result, "lowering", 10.0))
    folder = tmp_path / "mix"
    shutil.copytree(run_dir, folder)
    mixed = replace(
        result, tasks=tasks, energy=replace(result.energy, optimal=replace(result.energy.optimal, thermal=None))
    )
    (folder / "result.json").write_text(json.dumps(mixed.to_json()))
    assert main(["report", str(folder)]) == 0
    html = (folder / "report.html").read_text()
    assert "<h2>Thermal state</h2>" in html  # the mix's top level has no thermal state: the tasks carry it
    duty = html.split("<td>duty</td>")[1].split("</tr>")[0]
    assert f"lifting: {result.energy.duty}; lowering: {result.energy.duty}" in duty.replace("&#x27;", "'")
    thermal = html.split("<h2>Thermal state</h2>")[1].split("<h2>")[0]
    for task in ("lifting", "lowering"):
        for motor, t in result.energy.optimal.thermal.items():
            assert f"<td>{task}</td><td>{motor}</td>" in thermal
            assert f"{t.peak_winding_temperature_C:.1f} / {t.max_winding_temperature_C:.0f} °C" in thermal


def test_report_names_each_active_limit_in_words_beside_its_row(run_dir: Path, result: Result) -> None:
    """Sensitivities and the least margin read as a designer's words, the result.json row name kept beside them."""
    from hiab_sim.study.report.summary import limit_in_words

    html = (run_dir / "report.html").read_text()
    sensitivities = html.split("<h2>Sensitivities</h2>")[1].split("<h2>")[0]
    assert result.sensitivity is not None and result.sensitivity.multipliers
    for m in result.sensitivity.multipliers:
        words = limit_in_words(m.constraint)
        assert words != m.constraint  # every active row of the small study has words
        assert esc(f"{words} ({m.constraint})") in sensitivities
    worst = result.optimal.worst_constraint.name
    assert esc(limit_in_words(worst)) in html.split("least margin at the optimum")[1].split("</tr>")[0]


def test_report_says_how_a_tolerance_corner_is_named(run_dir: Path, result: Result) -> None:
    """'at the corner +-+--- design' is decoded on the page: one sign per decision variable, in their order."""
    assert result.buildable is not None
    html = (run_dir / "report.html").read_text()
    section = html.split("<h2>Constraints and margins at the optimum</h2>")[1].split("<h2>")[0]
    names = ", ".join(result.buildable.lengths.names)
    assert f"named by its signs: ±{1e3 * result.buildable.tolerance_m:g} mm on each of {names}, in order" in section


def test_report_calls_multipliers_rough_when_their_fit_leaves_the_gradient_unexplained(
    run_dir: Path, result: Result, tmp_path: Path
) -> None:
    """A KKT fit residual of 0.15 (a duty mix's, measured) gets a warning; the small study's own fit none."""
    import shutil
    from dataclasses import replace

    from hiab_sim.design_report.analysis import ROUGH_FIT

    assert result.sensitivity is not None and result.sensitivity.kkt_residual <= ROUGH_FIT
    assert "read them as rough" not in (run_dir / "report.html").read_text()
    folder = tmp_path / "rough"
    shutil.copytree(run_dir, folder)
    rough = replace(result, sensitivity=replace(result.sensitivity, kkt_residual=0.15))
    (folder / "result.json").write_text(json.dumps(rough.to_json()))
    assert main(["report", str(folder)]) == 0
    section = (folder / "report.html").read_text().split("<h2>Sensitivities</h2>")[1].split("<h2>")[0]
    assert "leave 15 % of the objective&#x27;s gradient unexplained" in section and "read them as rough" in section

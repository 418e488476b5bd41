"""The answer first: ``hiab-sim optimize`` ends with a short summary, and ``summary.md`` holds the same text."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.results.read import read_result
from hiab_sim.study.report.summary import SUMMARY_FILE, before_after, limit_in_words

#: End-to-end runs of whole commands (optimize, report, Chromium, tutorials): not in the fast tier.
pytestmark = pytest.mark.e2e


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The small study optimised once through the CLI (no figures, no video); its folder and stdout."""
    import contextlib
    import io

    folder = tmp_path_factory.mktemp("summary")
    study = write_study(folder, small_study())
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        assert main(["optimize", str(study), "--out", str(folder / "out"), "--no-video", "--no-figures"]) == 0
    return folder / "out", stdout.getvalue()


def test_console_ends_with_the_summary_that_summary_md_holds(run: tuple[Path, str]) -> None:
    """The last lines printed are exactly summary.md; without --verbose nothing else but that summary is printed."""
    folder, printed = run
    saved = (folder / SUMMARY_FILE).read_text()
    assert printed.endswith(saved)
    assert printed.strip() == saved.strip()  # no iteration lines, no KKT report before it
    assert len(saved.splitlines()) <= 15  # one screen


def test_summary_numbers_are_the_results_own(run: tuple[Path, str]) -> None:
    """The buildable lengths [mm], their moves and the energies before/after are read from result.json."""
    folder, _ = run
    text = (folder / SUMMARY_FILE).read_text()
    r = read_result(folder)
    assert r.buildable is not None and r.energy is not None
    built, initial = r.buildable.lengths, r.initial.lengths
    assert f"base pivot to boom hinge {built.lift.L * 1e3:.0f} ({(built.lift.L - initial.lift.L) * 1e3:+.0f})" in text
    assert f"rod length {built.tilt.Lc * 1e3:.0f} ({(built.tilt.Lc - initial.tilt.Lc) * 1e3:+.0f})" in text
    assert f"{r.energy.initial.battery_energy_J / 1e3:.3f} kJ before" in text
    assert f"{r.energy.optimal.battery_energy_J / 1e3:.3f} kJ after" in text
    assert "at the battery" in text
    period = "per duty period (cycle and rest)" if r.energy.optimal.duty is not None else "per cycle"
    assert f"Energy {period} at the battery" in text  # the period the battery figure covers, named
    assert str(folder) in text and r.buildable.mjcf_command in text


def test_distinct_optima_are_ranked_by_the_objective_in_the_summary(run: tuple[Path, str]) -> None:
    """Two distinct optima: the line gives their objective's spread and where the reported (start 0's) one lies."""
    import dataclasses

    from hiab_sim.results.multistart import DistinctOptimum
    from hiab_sim.study.report.summary import summary_lines

    folder, _ = run
    r = read_result(folder)
    row = r.multistart.starts[0]
    optima = (
        DistinctOptimum(xi=(0.1,), cost_W2s=1.0, starts=(0,), objective_value=1003.0),
        DistinctOptimum(xi=(0.2,), cost_W2s=1.0, starts=(1, 2), objective_value=1000.0),
    )
    ms = dataclasses.replace(
        r.multistart,
        starts=(row, dataclasses.replace(row, start=1), dataclasses.replace(row, start=2)),
        converged_starts=3,
        same_optimum=False,
        distinct_optima=optima,
        objective="battery_energy",
        objective_unit="J",
    )
    text = "\n".join(summary_lines(dataclasses.replace(r, multistart=ms), folder))
    assert (
        "Starts: 3 of 3 converged, to 2 distinct local optima (their battery_energy within 0.3 % of the lowest; "
        "the result is start 0's, 0.3 % above the lowest)." in text
    )
    lowest = dataclasses.replace(ms, distinct_optima=(optima[1], optima[0]))
    assert "the result is start 0's, the lowest)." in "\n".join(
        summary_lines(dataclasses.replace(r, multistart=lowest), folder)
    )


def test_verbose_prints_the_iterations_before_the_summary(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--verbose adds the per-iteration lines (stderr) and the full report; the summary still comes last."""
    study = write_study(tmp_path, small_study())
    out = tmp_path / "out"
    assert main(["optimize", str(study), "--out", str(out), "--no-video", "--no-figures", "--verbose"]) == 0
    captured = capsys.readouterr()
    assert "iter" in captured.err.lower() or "it " in captured.err.lower()
    assert captured.out.endswith((out / SUMMARY_FILE).read_text())
    assert len(captured.out.splitlines()) > len((out / SUMMARY_FILE).read_text().splitlines()) + 3


def test_rerun_removes_the_earlier_simulation_too_and_says_so(
    run: tuple[Path, str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A fresh (quiet) run over an earlier one removes every earlier output, simulation.json too, and says which."""
    import shutil

    folder = tmp_path / "out"
    shutil.copytree(run[0], folder)
    (folder / "simulation.json").write_text(json.dumps({"stale": True}))
    (folder / "closed_loop.mp4").write_bytes(b"old")
    study = json.loads((folder / "owner.json").read_text())["study"]
    capsys.readouterr()
    assert main(["optimize", study, "--out", str(folder), "--no-video", "--no-figures", "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert not (folder / "simulation.json").exists() and not (folder / "closed_loop.mp4").exists()
    assert "removed all" in printed and "simulation.json" in printed and "closed_loop.mp4" in printed


@pytest.mark.parametrize(
    ("row", "words"),
    [
        ("envelope.lift.peak_torque", "lift motor peak torque"),
        ("stroke.tilt.x <= stroke", "tilt end of stroke"),
        (
            "working_range.lift.x >= 0 at the low end",
            "lift cylinder fully retracted over the working range at the lower",
        ),
        ("bound tilt.L up = 1.3 m", "tilt base pivot to boom hinge at its upper bound (1300 mm)"),
        ("tracking.position.x_tcp <= band", "TCP tracking band (position), TCP x (horizontal)"),
        ("tracking.velocity.xt2 >= band", "tracking band (velocity), joint xt2"),
        (
            "digging: buildable_range.boom.x <= stroke at the up end",
            "digging: boom end of stroke over the build range at the upper end of the joint range",
        ),
        ("grading: envelope.bucket.peak_torque", "grading: bucket motor peak torque"),
    ],
)
def test_constraint_rows_read_in_words(row: str, words: str) -> None:
    """Row names of the NLP become words a designer reads (no dots, no underscores, no 'x <= Lc')."""
    assert limit_in_words(row).startswith(words)
    assert limit_in_words(row.replace(" <= band", "")) == limit_in_words(row)


@pytest.mark.parametrize(
    ("before", "after", "change"),
    [(16300.0, 16045.0, "(-1.56 %)"), (-84.86, -87.38, "(-2.97 %)"), (-87.38, -84.86, "(+2.88 %)")],
)
def test_energy_change_is_signed_as_the_energy_moves(before: float, after: float, change: str) -> None:
    """Less energy after reads as a negative change, also for a regenerating cycle (negative energy)."""
    assert before_after(before, after).endswith(change)

"""The answer first: energy-map, pareto and sweep open their console output with the answer, save it, draw no bars.

Each command runs once on the tiny study (a few seconds each): its stdout begins with the text of
``summary.md`` in its output folder, that text holds the numbers of the command's own files
(``energy_map.json``, ``pareto.csv``, ``sweep.parquet`` and the points' ``result.json``), and
nothing reaches stderr (no progress bar or status line when the output is not a terminal).
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_study_small import TINY, small_study, write_study
from test_sweep import write_sweep

from hiab_sim.cli import main
from hiab_sim.cli.answer_output import ANSWER_FILE
from hiab_sim.results.read import read_result
from hiab_sim.sweep import runner
from hiab_sim.sweep.answers import knee_index
from hiab_sim.sweep.pareto import FrontPoint
from hiab_sim.sweep.table import read_table
from hiab_sim.terminal import StatusLine, progress_wanted

#: End-to-end runs of whole commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e


def _head_is_the_saved_answer(out: str, folder: Path) -> str:
    """The saved answer; asserts that stdout begins with it and that the details follow after a blank line."""
    saved = (folder / ANSWER_FILE).read_text()
    assert saved.strip() and out.startswith(saved)
    rest = out[len(saved) :]
    assert rest == "" or rest.startswith("\n")
    assert not list(folder.glob(f".{Path(ANSWER_FILE).stem}.*"))  # no temporary file left by the atomic write
    return saved


def test_energy_map_opens_with_the_best_mounting_and_its_battery_energy(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The first lines name the best feasible cell's lengths and its battery energy against the base design's."""
    study = write_study(tmp_path, small_study(**TINY))
    folder = tmp_path / "map"
    assert main(["energy-map", str(study), "--grid", "8", "--out", str(folder)]) == 0
    captured = capsys.readouterr()
    answer = _head_is_the_saved_answer(captured.out, folder)
    assert captured.err == ""
    s = json.loads((folder / "energy_map.json").read_text())
    best = s["best_feasible_cell"]
    assert best is not None
    lines = answer.splitlines()
    energy = next(line for line in lines if line.startswith("Battery energy per cycle at the battery"))
    assert f"{s['at_base']['battery_energy_J'] / 1e3:.3f} kJ at the base design" in energy
    assert f"{best['battery_energy_J'] / 1e3:.3f} kJ at the best" in energy
    for name in s["variables"]:
        value = best["xi_m"][["lift.L", "lift.Lc0", "lift.Lc", "tilt.L", "tilt.Lc0", "tilt.Lc"].index(name)]
        assert f"{name} = {value * 1e3:.0f} mm" in answer
    assert answer.index("Best feasible mounting") < answer.index("Files in")  # the answer before the files
    arrays = np.load(folder / "energy_map.npz")
    least = float(arrays["battery_energy_J"][arrays["feasible"]].min())  # the map's own grid, not the summary
    if least < best["battery_energy_J"]:
        assert "Least battery energy of a feasible mounting on the map: " in answer
        assert f"{least / 1e3:.3f} kJ" in answer
    else:
        assert "Least battery energy" not in answer


def test_energy_map_without_a_feasible_cell_says_why(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """lift.L x tilt.L, the rest at the start: no feasible cell; the answer says why and gives the base's energy."""
    study = write_study(tmp_path, small_study(**TINY))
    folder = tmp_path / "map"
    assert main(["energy-map", str(study), "--vars", "lift.L,tilt.L", "--grid", "6", "--out", str(folder)]) == 0
    answer = _head_is_the_saved_answer(capsys.readouterr().out, folder)
    s = json.loads((folder / "energy_map.json").read_text())
    assert s["best_feasible_cell"] is None  # the case of the issue: a map over lengths that keep no stroke feasible
    assert answer.splitlines()[2].startswith("No feasible cell of 36: ")
    assert f"{s['at_base']['battery_energy_J'] / 1e3:.3f} kJ" in answer
    assert "instead" in answer  # the hint which variables to map


def test_pareto_opens_with_the_ends_and_the_knee(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The answer names the plain optimum and the least peak force of pareto.csv, and a knee."""
    study = write_study(tmp_path, small_study(**TINY))
    folder = tmp_path / "front"
    assert main(["pareto", str(study), "--against", "peak_force", "--points", "4", "--out", str(folder)]) == 0
    captured = capsys.readouterr()
    answer = _head_is_the_saved_answer(captured.out, folder)
    assert captured.err == ""
    table = pd.read_csv(folder / "pareto.csv")
    ok = table[table["accepted"]]
    plain = next(line for line in answer.splitlines() if line.startswith("- plain optimum"))
    assert f"{table['criterion'].iloc[0] / 1e3:.3f} kN" in plain
    least = next(line for line in answer.splitlines() if line.startswith("- least peak actuator force reached"))
    assert f"{ok['criterion'].min() / 1e3:.3f} kN" in least
    assert "- knee" in answer


def test_sweep_opens_with_the_least_energy_point_and_draws_no_bar(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without --quiet and off a terminal: no bar on stderr; the answer names the point of least battery energy.

    The battery energy of the table is the points' own ``result.json`` figure (a round trip).
    """
    path = write_sweep(tmp_path, {"grid": {"payload": [0.0, 150.0]}})
    folder = tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(folder)]) == 0
    captured = capsys.readouterr()
    answer = _head_is_the_saved_answer(captured.out, folder)
    assert captured.err == ""
    frame, _ = read_table(folder / "sweep.parquet")
    for _, row in frame.iterrows():
        energy = read_result(folder / "points" / row["key"]).energy
        assert energy is not None
        assert row["opt_battery_energy_J"] == energy.optimal.battery_energy_J
        assert row["start_battery_energy_J"] == energy.initial.battery_energy_J
    best = frame.loc[frame["opt_battery_energy_J"].idxmin()]
    assert f"point {best['key']} (payload = {best['payload']})" in answer
    assert f"{best['opt_battery_energy_J'] / 1e3:.3f} kJ at its optimum" in answer
    spread = f"{frame['opt_battery_energy_J'].min() / 1e3:.3f} .. {frame['opt_battery_energy_J'].max() / 1e3:.3f} kJ"
    assert spread in answer


class _Stream(io.StringIO):
    def __init__(self, tty: bool) -> None:
        super().__init__()
        self.tty = tty

    def isatty(self) -> bool:
        return self.tty


@pytest.mark.parametrize(("out_tty", "err_tty"), [(False, True), (True, False), (False, False), (True, True)])
def test_progress_only_when_stdout_and_stderr_are_terminals(
    monkeypatch: pytest.MonkeyPatch, out_tty: bool, err_tty: bool
) -> None:
    """Redirecting either stream silences the sweep's bar and the status line; on two terminals both show."""
    err = _Stream(err_tty)
    monkeypatch.setattr(sys, "stdout", _Stream(out_tty))
    monkeypatch.setattr(sys, "stderr", err)
    both = out_tty and err_tty
    assert progress_wanted() is both
    bar = runner._bar(3, 0, True)
    assert (bar is not None) is both
    if bar is not None:
        bar.close()
    with StatusLine("working ..."):
        pass
    assert ("working ..." in err.getvalue()) is both


def _point(criterion: float, objective: float, accepted: bool = True) -> FrontPoint:
    return FrontPoint(criterion, criterion, objective, objective, "W^2 s", objective, (0.0,) * 6, accepted, "", 1)


def test_knee_is_the_point_farthest_from_the_chord() -> None:
    """On an L-shaped front the corner is the knee; a straight front, or one of two converged points, has none.

    By hand, with both axes scaled to the span between the ends, the points lie at x = 0, 0.5,
    0.75, 0.9, 1 and y = 0, 0.02, 0.06, 0.4, 1; their distances to the chord y = x are
    proportional to x - y = 0, 0.48, 0.69, 0.5, 0: the third point (8.5 kN) is the knee.
    """
    c = [10.0, 9.0, 8.5, 8.2, 8.0]
    f = [1.0, 1.01, 1.03, 1.2, 1.5]
    assert knee_index([_point(a, b) for a, b in zip(c, f, strict=True)]) == 2
    assert knee_index([_point(10.0 - k, 1.0 + 0.1 * k) for k in range(5)]) is None
    assert knee_index([_point(10.0, 1.0), _point(9.0, 1.1, False), _point(8.0, 1.2)]) is None

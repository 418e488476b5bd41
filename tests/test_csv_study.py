"""CSV tasks through ``hiab-sim optimize``: a CSV of the spiral gives the spiral's result; bad files exit 2."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from test_csv_reference import BAD_FILES
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.results.read import read_result
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.spec.study_file import study_from_dict

FLAGS = ["--no-video", "--quiet", "--no-figures"]


def _csv_study(folder: Path, csv: str) -> Path:
    data = small_study(name="csv")
    data["reference"] = {"kind": "csv", "file": csv}
    return write_study(folder, data, "csv_study.yaml")


@pytest.mark.parametrize("case", list(BAD_FILES))
def test_bad_csv_task_exits_2_naming_row_or_column_and_writes_nothing(
    tmp_path: Path, case: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every malformed trajectory file: exit status 2, the file and its row or column named, no output folder."""
    text, _, match = BAD_FILES[case]
    (tmp_path / "bad.csv").write_text(text)
    out = tmp_path / "out"
    assert main(["optimize", str(_csv_study(tmp_path, "bad.csv")), "--out", str(out), *FLAGS]) == 2
    err = capsys.readouterr().err
    assert "bad.csv" in err and "Traceback" not in err
    assert re.search(match, err), err
    assert not out.exists()


def test_missing_csv_task_exits_2_naming_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A task whose file does not exist: exit 2 naming the file, nothing written."""
    out = tmp_path / "out"
    assert main(["optimize", str(_csv_study(tmp_path, "nowhere.csv")), "--out", str(out), *FLAGS]) == 2
    assert "nowhere.csv" in capsys.readouterr().err and not out.exists()


@pytest.mark.e2e
def test_csv_written_from_the_spiral_reproduces_the_spiral_study(tmp_path: Path) -> None:
    """The small spiral study and the same study reading its spiral from a 100 Hz CSV reach the same optimum."""
    spiral = study_from_dict(small_study(), tmp_path / "s.yaml")
    kin = tr.TcpKinematics(spiral.crane)
    t = np.linspace(0.0, spiral.reference.duration, 626)
    ref = spiral.reference.sample(kin, t)
    rows = "\n".join(f"{ti:.4f},{x:.7f},{y:.7f},{xt:.7f}" for ti, (x, y, xt) in zip(t, ref.position, strict=True))
    (tmp_path / "spiral.csv").write_text("# the small study's spiral at 100 Hz\nt,x,y,xt2\n" + rows + "\n")
    results = {}
    for name, path in (("spiral", write_study(tmp_path, small_study())), ("csv", _csv_study(tmp_path, "spiral.csv"))):
        assert main(["optimize", str(path), "--out", str(tmp_path / name), *FLAGS]) == 0
        results[name] = read_result(tmp_path / name)
    a, b = results["spiral"], results["csv"]
    np.testing.assert_allclose(b.optimal.lengths.as_array(), a.optimal.lengths.as_array(), atol=2e-3)
    assert b.optimal.net_electrical_energy_J == pytest.approx(a.optimal.net_electrical_energy_J, rel=1e-2)
    assert b.recheck.max_violation_scaled <= 1e-6

"""CSV references: a file written from the spiral reproduces it; every bad file names its row or column."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from references_helper import pick_and_place_tasks

from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.motion import trajectory as tr
from hiab_sim.study.references.csv_file import CsvReference, read_table
from hiab_sim.study.references.kinds import PickAndPlace, reference_from_mapping
from hiab_sim.study.spec.study_file import load_study
from hiab_sim.study.spec.tasks import column_names

STUDY = load_study()
CRANE = STUDY.crane
NAMES = column_names(STUDY.model)  # the crane's columns: xt2 beyond x, y; its joints
KIN = tr.TcpKinematics(CRANE)
DURATION = STUDY.grid.duration
ROWS = np.linspace(0.0, DURATION, 251)  # a 40 Hz recording of the spiral
SPIRAL = STUDY.reference.sample(KIN, ROWS)
assert STUDY.reference.centre_joints is not None
SPIRAL_JOINTS = tr.inverse_kinematics(KIN, SPIRAL, STUDY.reference.centre_joints).position


def _write(path: Path, header: str, t: np.ndarray, columns: np.ndarray, comment: str = "# a test trajectory\n") -> Path:
    body = "\n".join(",".join(f"{v:.10g}" for v in (ti, *row)) for ti, row in zip(t, columns, strict=True))
    path.write_text(f"{comment}{header}\n{body}\n")
    return path


@pytest.mark.parametrize("form", ["tcp", "joints"])
def test_csv_of_the_spiral_reproduces_the_spiral_within_the_collocation_bands(tmp_path: Path, form: str) -> None:
    """A 40 Hz file of the spiral (TCP or joints), fitted, gives the spiral's r, dr, ddr within half the bands."""
    if form == "tcp":
        _write(tmp_path / "spiral.csv", "t,x,y,xt2", ROWS, SPIRAL.position)
    else:
        _write(tmp_path / "spiral.csv", "t, theta1, theta2, xt2", ROWS, SPIRAL_JOINTS)
    reference = reference_from_mapping(
        {"kind": "csv", "file": "spiral.csv"}, "tasks[2].reference", tmp_path, 1.0, NAMES
    )
    assert isinstance(reference, CsvReference) and reference.duration == pytest.approx(DURATION)
    reference.check_reach(KIN, CRANE)
    fine = STUDY.grid.fine_times()
    fitted = reference.sample(KIN, fine)
    spiral = STUDY.reference.sample(KIN, fine)
    band = STUDY.tracking
    for name, tol in (("position", band.position), ("velocity", band.velocity), ("acceleration", band.acceleration)):
        error = np.abs(getattr(fitted, name) - getattr(spiral, name)).max()
        assert error <= band.collocation_fraction * tol, name


def test_tcp_csv_without_telescope_column_holds_the_given_telescope(tmp_path: Path) -> None:
    """A ``t, x, y`` file with ``telescope: 0.4`` is the same reference as the file with xt2 = 0.4 written out."""
    xy = SPIRAL.position[:, :2]
    short = tmp_path / "xy.csv"  # any column order
    short.write_text("x,y,t\n" + "\n".join(f"{x:.10g},{y:.10g},{t:.10g}" for t, (x, y) in zip(ROWS, xy, strict=True)))
    full = _write(tmp_path / "xyt.csv", "t,x,y,xt2", ROWS, np.column_stack([xy, np.full(len(ROWS), 0.4)]))
    a = CsvReference(read_table(short, NAMES), NAMES, telescope=0.4).sample(KIN, STUDY.grid.times())
    b = CsvReference(read_table(full, NAMES), NAMES).sample(KIN, STUDY.grid.times())
    np.testing.assert_allclose(a.position, b.position, atol=1e-12)
    np.testing.assert_allclose(a.acceleration, b.acceleration, atol=1e-9)


def _rows(text_rows: list[str], header: str = "t,x,y,xt2") -> str:
    return "# comment line 1\n" + header + "\n" + "\n".join(text_rows) + "\n"


GOOD = [f"{t:.4f},{x:.6f},{y:.6f},{xt:.6f}" for t, (x, y, xt) in zip(ROWS, SPIRAL.position, strict=True)]


def _replace(rows: list[str], index: int, row: str) -> list[str]:
    out = list(rows)
    out[index] = row
    return out


# Row numbers are file lines: line 1 is the comment, line 2 the header, data row i is line i + 3.
BAD_FILES = {
    "header-unknown-column": (_rows(GOOD, "t,x,z,xt2"), ConfigError, r"row 2: header columns \['t', 'x', 'z', 'xt2'\]"),
    "header-missing-column": (_rows([r.rsplit(",", 2)[0] for r in GOOD], "t,x"), ConfigError, r"row 2: header"),
    "no-header": (_rows(GOOD[1:], GOOD[0]), ConfigError, r"row 2: header columns"),
    "unsorted-time": (
        _rows(_replace(GOOD, 10, "0.1,3.0,0.3,0.4")),
        InvalidInputError,
        r"row 13, column 't' = 0.1 s .*row 12 has t = 0.225 s",
    ),
    "repeated-time": (
        _rows(_replace(GOOD, 10, GOOD[9])),
        InvalidInputError,
        r"row 13, column 't' = 0.225 s .*increase strictly",
    ),
    "nan": (_rows(_replace(GOOD, 20, "0.4,nan,0.3,0.4")), InvalidInputError, r"row 23 \(t = 0.4 s\), column 'x' = nan"),
    "not-a-number": (_rows(_replace(GOOD, 5, "0.1,3.0,abc,0.4")), ConfigError, r"row 8, column 'y': not a number"),
    "short-row": (_rows(_replace(GOOD, 7, "0.14,3.0,0.3")), ConfigError, r"row 10: 3 values; the header has 4"),
    "too-few-rows": (_rows(GOOD[:4]), InvalidInputError, r"rows = 4 .*at least 7"),
    "jump-the-fit-misses": (
        _rows(_replace(GOOD, 100, "2.5000,3.5,0.3,0.4")),
        InvalidInputError,
        r"row 103 \(t = 2.5 s\), column 'x' .*fit",
    ),
    "empty": ("# nothing\n\n", ConfigError, r"no header row"),
}


@pytest.mark.parametrize("case", list(BAD_FILES))
def test_bad_csv_raises_naming_file_row_and_column(tmp_path: Path, case: str) -> None:
    """Each malformed file raises one error naming the file and the row (and column or time)."""
    text, error, match = BAD_FILES[case]
    path = tmp_path / f"{case}.csv"
    path.write_text(text)
    with pytest.raises(error, match=match) as info:
        CsvReference(read_table(path, NAMES), NAMES)
    assert str(path) in str(info.value)


def test_missing_csv_file_names_it(tmp_path: Path) -> None:
    """A missing file raises :class:`ConfigError` naming the path."""
    with pytest.raises(ConfigError, match=r"cannot read trajectory file .*nowhere.csv"):
        reference_from_mapping({"kind": "csv", "file": "nowhere.csv"}, "reference", tmp_path, 1.0, NAMES)


def test_unreachable_tcp_row_names_row_and_time(tmp_path: Path) -> None:
    """A TCP row beyond the crane's reach raises naming its line and time, before any fit sample is checked."""
    far = SPIRAL.position.copy()
    far[150:160, 0] += 3.0  # 3 m further out than the spiral, for 0.25 s
    path = _write(tmp_path / "far.csv", "t,x,y,xt2", ROWS, far)
    reference = CsvReference(read_table(path, NAMES), NAMES, fit_tolerance=10.0)
    message = r"far.csv row 153 \(t = 3.75 s\), columns x, y, xt2 = 'TCP .* out of the crane's reach"
    with pytest.raises(InvalidInputError, match=message):
        reference.check_reach(KIN, CRANE)


def test_joint_row_outside_the_range_names_row_and_column(tmp_path: Path) -> None:
    """A joint row outside the crane's joint range raises naming line, time and column."""
    joints = SPIRAL_JOINTS.copy()
    joints[200:, 2] = 1.3  # the telescope beyond its 1.1 m range from t = 5 s
    path = _write(tmp_path / "joints.csv", "t,theta1,theta2,xt2", ROWS, joints)
    reference = CsvReference(read_table(path, NAMES), NAMES, fit_tolerance=10.0)
    with pytest.raises(InvalidInputError, match=r"joints.csv row 203 \(t = 5 s\), column 'xt2' = 1.3 m"):
        reference.check_reach(KIN, CRANE)


@pytest.mark.parametrize(
    ("header", "telescope", "match"),
    [("t,x,y,xt2", 0.4, "not both"), ("t,x,y", None, "neither"), ("t,theta1,theta2,xt2", 0.4, "remove")],
)
def test_telescope_given_once(tmp_path: Path, header: str, telescope: float | None, match: str) -> None:
    """The telescope comes from the file's xt2 column or the task's ``telescope``, exactly once."""
    n = len(header.split(",")) - 1
    path = _write(
        tmp_path / "tele.csv", header, ROWS, np.column_stack([SPIRAL_JOINTS[:, :2], SPIRAL.position[:, 2]])[:, :n]
    )
    with pytest.raises(ConfigError, match=match):
        CsvReference(read_table(path, NAMES), NAMES, telescope=telescope)


@settings(max_examples=15, deadline=None)
@given(task=pick_and_place_tasks(rise=1.0, shortest_move=5.0, longest_dwell=2.0))
def test_csv_of_any_pick_and_place_reproduces_it_within_the_collocation_bands(
    tmp_path_factory: pytest.TempPathFactory, task: PickAndPlace
) -> None:
    """A 40 Hz file (1 um resolution) of a pick-and-place, fitted, gives its r, dr, ddr within half the bands."""
    rows = np.linspace(0.0, task.duration, int(np.ceil(task.duration * 40.0)) + 1)
    path = tmp_path_factory.mktemp("pp") / "pp.csv"
    body = "\n".join(
        f"{t:.6f},{x:.6f},{y:.6f},{xt:.6f}" for t, (x, y, xt) in zip(rows, task.sample(KIN, rows).position, strict=True)
    )
    path.write_text("t,x,y,xt2\n" + body + "\n")
    fitted = CsvReference(read_table(path, NAMES), NAMES)
    grid = np.linspace(0.0, task.duration, 401)
    a, b = fitted.sample(KIN, grid), task.sample(KIN, grid)
    band = STUDY.tracking
    for name, tol in (("position", band.position), ("velocity", band.velocity), ("acceleration", band.acceleration)):
        assert np.abs(getattr(a, name) - getattr(b, name)).max() <= band.collocation_fraction * tol, name

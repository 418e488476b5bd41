"""A task's reference from a trajectory file: TCP ``t, x, y[, xt2]`` or joints ``t, theta1, theta2, xt2``.

The columns are the machine's: the TCP form is ``t, x, y`` and each further tracked coordinate by
name (the crane's ``xt2``, an excavator's ``tcp_angle``); the joint form ``t`` and every joint by
name. The names come from the study's machine (its description), never from here.

File format: comma-separated, SI units (s, m, rad), one header row naming the columns (any
order), then one sample per row; blank lines and lines starting with ``#`` are skipped (use them
to say where the data comes from). Rows are named by their line number in the file, as an
editor shows it. Times must increase strictly; they are shifted so the first row is t = 0.

The rows are fitted by a clamped quintic B-spline (:class:`~hiab_sim.study.motion.trajectory.SplineBasis`,
``control_points`` uniform control points over the file's duration) in least squares, at rest
(zero velocity and acceleration) at both ends, as the NLP's trajectories are
(:func:`~hiab_sim.study.motion.trajectory.fit_coefficients` with the positions only). The fit is the
reference: it is smooth, has exact derivatives, and is sampled on any grid. It must pass every
row within ``fit_tolerance``; a row it misses (noisy data, a file that does not start or end at
rest, too few control points) is named.

TCP form: the fit is r = (x, y, xt2) directly; without an ``xt2`` column the telescope is held at
the task's ``telescope`` [m] (prescribed, see :mod:`hiab_sim.study.references.kinds`); a machine
with one further tracked coordinate may likewise hold it at ``telescope`` [its unit]. Joint form:
the fit is the joints and r follows by the planar TCP kinematics with exact rates.
Every row is checked against the machine's reach and joint ranges (its IK,
:mod:`hiab_sim.study.motion.workspace`), then the fitted reference every 10 ms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.motion.trajectory import JointTrajectory, Reference, SplineBasis, fit_coefficients
from hiab_sim.study.motion.workspace import check_workspace, dense_times, describe_point
from hiab_sim.yaml_fields import mapping, number, positive

if TYPE_CHECKING:
    from hiab_sim.study.machines.protocol import Kinematics, StudyMachine

#: A machine's column names: its tracked coordinates beyond the TCP's x, y, and its joints (from its description).
ColumnNames = tuple[tuple[str, ...], tuple[str, ...]]


def forms(extra: tuple[str, ...], joints: tuple[str, ...]) -> dict[frozenset[str], str]:
    """Accepted column sets (any order) and the form they give, for a machine's tracked ``extra`` and ``joints``."""
    out = {frozenset({"t", "x", "y", *extra}): "tcp", frozenset({"t", *joints}): "joints"}
    if len(extra) == 1:
        out[frozenset({"t", "x", "y"})] = "tcp"  # the one further coordinate held at the task's value
    return out


DEGREE = 5
#: Default knot spacing of the fit [s]: the seed's 22 control points over 6.25 s space knots ~0.37 s.
KNOT_SPACING = 0.25


@dataclass(frozen=True)
class CsvTable:
    """Rows of a trajectory file: ``columns`` as in the header, ``values`` (R, C), ``lines`` (R,) numbers."""

    path: str
    columns: tuple[str, ...]
    values: Array
    lines: tuple[int, ...]


def read_table(path: Path, names: ColumnNames) -> CsvTable:
    """Parse a trajectory file (module docstring); malformed files raise :class:`ConfigError`.

    ``names``: the machine's tracked coordinates beyond x, y and its joints
    (:func:`hiab_sim.study.spec.tasks.column_names` of its study machine).
    """
    accepted = forms(*names)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise ConfigError(f"cannot read trajectory file {path}: {error.strerror or error}") from None
    rows = [(n, line.strip()) for n, line in enumerate(text.splitlines(), start=1)]
    rows = [(n, line) for n, line in rows if line and not line.startswith("#")]
    if not rows:
        raise ConfigError(f"{path}: no header row and no data")
    head_line, head = rows[0]
    columns = tuple(c.strip() for c in head.split(","))
    if accepted.get(frozenset(columns)) is None or len(set(columns)) != len(columns):
        order = ("t", "x", "y", *names[0], *names[1])
        expected = "; ".join(", ".join(sorted(f, key=order.index)) for f in accepted)
        raise ConfigError(f"{path} row {head_line}: header columns {list(columns)}; expected one of: {expected}")
    values = np.empty((len(rows) - 1, len(columns)))
    for i, (n, line) in enumerate(rows[1:]):
        cells = [c.strip() for c in line.split(",")]
        if len(cells) != len(columns):
            raise ConfigError(
                f"{path} row {n}: {len(cells)} values; the header has {len(columns)} ({', '.join(columns)})"
            )
        for j, cell in enumerate(cells):
            try:
                values[i, j] = float(cell)
            except ValueError:
                raise ConfigError(f"{path} row {n}, column '{columns[j]}': not a number: {cell!r}") from None
    return CsvTable(str(path), columns, values, tuple(n for n, _ in rows[1:]))


@dataclass(frozen=True)
class CsvReference:
    """Reference fitted to a trajectory file (module docstring).

    Attributes:
        table: The file's rows.
        telescope: xt2 [m] held constant for a TCP file without an ``xt2`` column, else None.
        control_points: Control points of the fit (default: one knot span per 0.25 s, + degree).
        fit_tolerance: Largest allowed miss of the fit at a row [m or rad].

    """

    table: CsvTable
    names: ColumnNames
    telescope: float | None = None
    control_points: int | None = None
    fit_tolerance: float = 5e-3
    kind: ClassVar[str] = "csv"
    form: str = field(init=False)
    time: Array = field(init=False, repr=False)
    coefficients: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        tab, columns = self.table, self.table.columns
        form = forms(*self.names)[frozenset(columns)]
        extra = self.names[0]
        object.__setattr__(self, "form", form)
        if len(tab.values) < DEGREE + 2:
            raise InvalidInputError(f"{tab.path} rows", len(tab.values), f"need at least {DEGREE + 2} data rows")
        bad = ~np.isfinite(tab.values)
        if bad.any():
            i, j = np.argwhere(bad)[0]
            when = f" (t = {tab.values[i, columns.index('t')]:.6g} s)" if columns[j] != "t" else ""
            raise InvalidInputError(
                f"{tab.path} row {tab.lines[i]}{when}, column '{columns[j]}'", tab.values[i, j], "must be finite"
            )
        t = tab.values[:, columns.index("t")]
        step = np.diff(t)
        if np.any(step <= 0.0):
            i = int(np.argmax(step <= 0.0)) + 1
            raise InvalidInputError(
                f"{tab.path} row {tab.lines[i]}, column 't'",
                float(t[i]),
                f"times must increase strictly (row {tab.lines[i - 1]} has t = {t[i - 1]:.6g} s)",
                "s",
            )
        if form == "tcp" and (set(extra) <= set(columns)) == (self.telescope is not None):
            raise ConfigError(
                f"{tab.path}: give the telescope either as an '{extra[-1]}' column or as the task's 'telescope', not "
                + ("both" if self.telescope is not None else "neither")
            )
        if form == "joints" and self.telescope is not None:
            raise ConfigError(f"{tab.path}: a joint file has its own joint columns; remove the task's 'telescope'")
        _require(self.fit_tolerance > 0.0, "fit_tolerance", self.fit_tolerance, "must be > 0")
        time = t - t[0]
        object.__setattr__(self, "time", time)
        basis = self.basis()
        spans = np.unique(basis.knots)
        counts = np.histogram(time, bins=spans)[0]
        if np.any(counts == 0):
            k = int(np.argmax(counts == 0))
            raise InvalidInputError(
                f"{tab.path} control_points",
                basis.n,
                f"no rows between t = {spans[k]:.6g} and {spans[k + 1]:.6g} s: use fewer control points or more rows",
            )
        data = self._data()
        joints = JointTrajectory(time, data, np.zeros_like(data), np.zeros_like(data))
        coefficients = fit_coefficients(basis, joints, rate_weight=0.0)
        object.__setattr__(self, "coefficients", coefficients)
        miss = np.abs(basis.matrix(time) @ coefficients.T - data)
        i, j = np.unravel_index(int(np.argmax(miss)), miss.shape)
        if miss[i, j] > self.fit_tolerance:
            name = self._fit_columns()[j]
            raise InvalidInputError(
                f"{tab.path} row {tab.lines[i]} (t = {t[i]:.6g} s), column '{name}'",
                float(miss[i, j]),
                f"the B-spline fit ({basis.n} control points, at rest at both ends) misses the row by more than "
                f"fit_tolerance = {self.fit_tolerance:.6g}: smooth the data, start and end at rest, "
                "or add control points",
            )

    @property
    def duration(self) -> float:
        """Time from the first to the last row [s]."""
        return float(self.time[-1])

    def basis(self) -> SplineBasis:
        """The fit's clamped quintic B-spline basis on [0, duration]."""
        n = self.control_points or math.ceil(self.duration / KNOT_SPACING) + DEGREE
        return SplineBasis(n, DEGREE, self.duration)

    def _fit_columns(self) -> tuple[str, ...]:
        return ("x", "y", *self.names[0]) if self.form == "tcp" else self.names[1]

    def _data(self) -> Array:
        """The fitted columns (R, n): (x, y, tracked...) or the joints."""
        tab = self.table
        cols = [tab.values[:, tab.columns.index(c)] for c in self._fit_columns() if c in tab.columns]
        if len(cols) < len(self._fit_columns()):
            assert self.telescope is not None
            cols.append(np.full(len(tab.values), self.telescope))
        return np.column_stack(cols)

    def sample(self, kin: Kinematics, times: Array) -> Reference:
        """Reference r = (x, y, xt2) and its rates from the fit at ``times`` [s] (0 = the first row)."""
        t = np.asarray(times, dtype=float)
        B, dB, ddB = self.basis().matrices(t)
        c = self.coefficients.T
        q, dq, ddq = B @ c, dB @ c, ddB @ c
        if self.form == "joints":
            s = kin.samples(q, dq, ddq)
            q, dq, ddq = s.position, s.velocity, s.acceleration
        return Reference(time=t, position=q, velocity=dq, acceleration=ddq, z=kin.z, centre=(q[0, 0], q[0, 1]))

    def check_reach(self, kin: Kinematics, model: StudyMachine | Crane) -> None:
        """Every row, then the fit every 10 ms, within the machine's reach and joint ranges."""
        if isinstance(model, Crane):
            from hiab_sim.study.machines.crane_model import CraneModel

            model = CraneModel(model)
        tab, data = self.table, self._data()
        t = tab.values[:, tab.columns.index("t")]
        if self.form == "tcp":
            error = self.row_reach_error(model, out_of_reach_only=False)
            if error is not None:
                raise error
        else:
            ranges = model.joint_ranges()
            units = model.joint_units
            for j, (name, (lo, hi)) in enumerate(zip(self._fit_columns(), ranges, strict=True)):
                out = (data[:, j] < lo) | (data[:, j] > hi)
                if np.any(out):
                    i = int(np.argmax(out))
                    raise InvalidInputError(
                        f"{tab.path} row {tab.lines[i]} (t = {t[i]:.6g} s), column '{name}'",
                        float(data[i, j]),
                        f"must lie in the machine's range [{lo:.6g}, {hi:.6g}]",
                        units[j],
                    )
        check_workspace(model, self.sample(kin, dense_times(self.duration)), where=f"{tab.path} fit")

    def row_reach_error(self, model: StudyMachine, out_of_reach_only: bool = True) -> InvalidInputError | None:
        """The error naming the file, row, time and columns of the first TCP-form row the machine cannot reach.

        ``out_of_reach_only``: only a row its inverse kinematics cannot reach at all (reason 1 of
        :meth:`~hiab_sim.study.machines.protocol.StudyMachine.reach`); else also one needing a joint
        outside its range or a stroke outside [0, stroke]. None when every row passes, or for a joint-form file.
        """
        if self.form != "tcp":
            return None
        tab, data = self.table, self._data()
        start, size = 0, 1
        while True:  # blocks of doubling size: an unreachable row costs a grid of IK starts, so stop at the first
            if start >= len(data):
                return None
            reach = model.reach(data[start : start + size])
            bad = np.flatnonzero(reach.status == 1 if out_of_reach_only else reach.status != 0)
            if len(bad):
                break
            start, size = start + size, 2 * size
        i = start + int(bad[0])
        status = int(reach.status[bad[0]])
        t = tab.values[i, tab.columns.index("t")]
        columns = ", ".join(c for c in self._fit_columns() if c in tab.columns)
        return InvalidInputError(
            f"{tab.path} row {tab.lines[i]} (t = {t:.6g} s), columns {columns}",
            describe_point(model, data[i]),
            f"the point {reach.reasons[status]}",
        )

    @classmethod
    def from_mapping(cls, data: Any, where: str, folder: Path, names: ColumnNames) -> CsvReference:
        """Read ``{kind: csv, file, telescope?, control_points?, fit_tolerance?}``; ``file`` relative to ``folder``."""
        d = mapping(data, where, {"kind", "file", "telescope", "control_points", "fit_tolerance"}, {"file"})
        path = Path(str(d["file"]))
        path = path if path.is_absolute() else folder / path
        points = d.get("control_points")
        if points is not None and (isinstance(points, bool) or not isinstance(points, int) or points < DEGREE + 2):
            raise InvalidInputError(f"{where}.control_points", points, f"must be an integer >= {DEGREE + 2}")
        telescope = d.get("telescope")
        return cls(
            table=read_table(path, names),
            telescope=None if telescope is None else number(telescope, f"{where}.telescope"),
            names=names,
            control_points=points,
            fit_tolerance=positive(d.get("fit_tolerance", 5e-3), f"{where}.fit_tolerance"),
        )


def _require(ok: bool, name: str, value: float, allowed: str) -> None:
    if not ok:
        raise InvalidInputError(name, value, allowed)

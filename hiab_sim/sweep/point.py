"""One sweep point on a worker: write its study, run the optimisation, return one table row.

:func:`run_point` is what an executor (local process or Dask worker) runs; it takes and returns
plain picklable data. A point that fails (an infeasible start, a solver failure, anything else)
returns a row with ``status = "failed"`` and the message, so the sweep goes on.
"""

from __future__ import annotations

import json
import math
import tempfile
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from hiab_sim.results.schema import Result

#: Result columns of a row before the optimum's decision variables (:func:`result_columns`).
RUN_COLUMNS = ("status", "message", "iterations", "wall_time_s")
#: Result columns of a row after them, in table order.
VALUE_COLUMNS = (
    "start_net_energy_J",
    "opt_net_energy_J",
    "start_drawn_energy_J",
    "opt_drawn_energy_J",
    "start_battery_energy_J",
    "opt_battery_energy_J",
    "start_cost_W2s",
    "opt_cost_W2s",
    "net_energy_saved_percent",
    "max_violation",
    "recheck_max_violation",
    "worst_constraint",
    "smallest_margin",
)


def design_column(name: str) -> str:
    """The column of the optimum's decision variable ``name`` (``lift.L`` -> ``opt_lift_L_m``) [m]."""
    return f"opt_{name.replace('.', '_')}_m"


def result_columns(design_names: tuple[str, ...]) -> tuple[str, ...]:
    """Result columns of a row, in table order (the parameter columns come first, then these)."""
    return (*RUN_COLUMNS, *(design_column(n) for n in design_names), *VALUE_COLUMNS)


#: Columns that differ between two runs of the same point (timing only).
TIMING_COLUMNS = ("wall_time_s",)


@dataclass(frozen=True)
class PointTask:
    """What a worker needs: the point's key and values, its study mapping and EMLA mapping (or None)."""

    key: str
    values: dict[str, Any]
    study: dict[str, Any]
    emla: dict[str, Any] | None
    study_file: str  # the base study's path (names the study; relative paths are already absolute)
    design_names: tuple[str, ...]  # the study's decision variables, in the order of Xi


@dataclass(frozen=True)
class PointOutcome:
    """A row for the table and the run's result.json text (None for a failed point)."""

    key: str
    row: dict[str, Any]
    result_json: str | None


def row_from_result(result: Result, design_names: tuple[str, ...]) -> dict[str, Any]:
    """The result columns of one finished run (the one place a sweep reads a run's result).

    ``design_names`` are the study's decision variables in the order of Xi (the optimum's values
    go to :func:`design_column` of each, in m).
    """
    start, opt, solver = result.initial, result.optimal, result.solver
    energy = result.energy  # the battery's energy at the study's duty; NaN where the result has no battery model
    row: dict[str, Any] = {
        "status": "ok",
        "message": solver.message,
        "iterations": solver.iterations,
        "wall_time_s": solver.total_wall_time_s,
    }
    for name, value in zip(design_names, opt.lengths.as_array(), strict=True):
        row[design_column(name)] = float(value)
    row.update(
        start_net_energy_J=start.net_electrical_energy_J,
        opt_net_energy_J=opt.net_electrical_energy_J,
        start_drawn_energy_J=start.drawn_energy_summed_drives_J,
        opt_drawn_energy_J=opt.drawn_energy_summed_drives_J,
        start_battery_energy_J=math.nan if energy is None else energy.initial.battery_energy_J,
        opt_battery_energy_J=math.nan if energy is None else energy.optimal.battery_energy_J,
        start_cost_W2s=start.collocation_cost_W2s,  # costf2 on the collocation grid, whatever the objective
        opt_cost_W2s=opt.collocation_cost_W2s,
        net_energy_saved_percent=result.improvement.net_energy_saved_percent,
        max_violation=solver.max_violation_scaled,
        recheck_max_violation=result.recheck.max_violation_scaled,
        worst_constraint=opt.worst_constraint.name,
        smallest_margin=opt.worst_constraint.scaled_margin,
    )
    return row


def failed_row(message: str, wall_time: float, columns: tuple[str, ...]) -> dict[str, Any]:
    """The result ``columns`` of a failed point: its message, NaN numbers."""
    row: dict[str, Any] = {c: math.nan for c in columns}
    row.update(status="failed", message=message, iterations=-1, wall_time_s=wall_time, worst_constraint="")
    return row


def run_point(task: PointTask) -> PointOutcome:
    """Optimise one point's study (no figures, no video) and return its row."""
    from hiab_sim.study.run import run_study
    from hiab_sim.study.spec.study_file import study_from_dict

    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="hiab-sweep-") as tmp:
        folder = Path(tmp)
        try:
            study_map = dict(task.study)
            if task.emla is not None:
                emla_file = folder / "emla.yaml"
                emla_file.write_text(yaml.safe_dump(task.emla, sort_keys=False))
                study_map["emla"] = str(emla_file)
            study = study_from_dict(study_map, task.study_file)
            output = run_study(study, folder / "run", progress=None, figures=False)
            row = row_from_result(output.result, task.design_names)
            text: str | None = json.dumps(output.result.to_json(), indent=2) + "\n"
        except Exception as error:  # any failure of one point is recorded, the sweep goes on
            message = f"{type(error).__name__}: {error}" if str(error) else traceback.format_exc(limit=1)
            columns = result_columns(task.design_names)
            row, text = failed_row(message.splitlines()[0], time.perf_counter() - t0, columns), None
    return PointOutcome(task.key, {**task.values, **row}, text)

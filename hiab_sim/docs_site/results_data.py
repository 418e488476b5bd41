"""The run data behind the results pages: the declared fields of a run folder, recorded, read back and compared.

A results page never reads a run folder: ``docs/results/data/<study>.json`` holds the few numbers it
shows, copied from the folder's ``result.json`` (:data:`RESULT_FIELDS`) and, when ``hiab-sim
simulate`` wrote one, ``simulation.json`` (:data:`SIMULATION_FIELDS`), at the same paths as there
(``result.energy.optimal.battery_energy_J`` is ``result.json`` -> ``energy.optimal.battery_energy_J``),
so every number on a page is traceable to the run that made it. A field is a dotted path whose ``*``
steps over every key of an object or every item of a list; a path a run does not have (a section its
study does not write) is left out, and a page that needs it fails to render naming the file and path.

:func:`differences` decides whether recorded data are still current against a fresh run's, within
the tolerances stated below; the CI tests apply it to the studies they can afford to re-run.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from hiab_sim.atomic_io import write_atomic
from hiab_sim.crane.description import CHAIN_NAMES
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import parse_json

#: Where the committed data live (one JSON file per study, named after the study).
DATA_DIR = Path(__file__).resolve().parents[2] / "docs" / "results" / "data"
#: How far a recorded number may be from a fresh run's, relative: SLSQP's and IPOPT's stopping points
#: move with round-off on another CPU, which moves the optimum's energies by up to ~1e-4 relative.
RELATIVE_TOLERANCE = 2e-3
#: Absolute floor of that comparison, in the number's own unit (for numbers that are zero or nearly).
ABSOLUTE_FLOOR = 1e-6
#: Iteration counts may differ by this fraction (at least one iteration): the stopping test is met a
#: step earlier or later when the last digits move.
ITERATION_TOLERANCE = 0.1
#: Round-off quantities (constraint violations, differences between the two ID paths) are current when
#: both are at most this large (the optimiser's feasibility tolerance, 1e-6 scaled).
ROUND_OFF_LIMIT = 1e-6
#: Leaf names compared as round-off (:data:`ROUND_OFF_LIMIT`).
ROUND_OFF_KEYS = frozenset({"max_violation", "max_violation_scaled", "force_difference_between_paths_N"})
#: Leaf names not compared at all: wall times depend on the machine and its load, not on the model.
NOT_COMPARED_KEYS = frozenset({"wall_time_s", "total_wall_time_s"})

_DESIGN = (
    "lengths",
    "net_electrical_energy_J",
    "drawn_energy_summed_drives_J",
    "energy_breakdown_J.copper",
    "actuators.*.peak_force_N",
    "actuators.*.net_energy_J",
    "tracking_error.position_m",
)
_ENERGY = (
    "battery_energy_J",
    "costf2_W2s",
    "drawn_energy_J",
    "net_energy_J",
    "thermal.*.rms_torque_Nm",
    "thermal.*.continuous_torque_Nm",
    "thermal.*.peak_winding_temperature_C",
    "thermal.*.max_winding_temperature_C",
    "drive_loss_energy_J.*.*",
    "drive_loss_smoothing_J",
    "smoothing_bound_J",
)
_HYDRAULIC = (
    "load_sensing.input_energy_J",
    "load_sensing.system_efficiency",
    "constant_pressure.input_energy_J",
    "constant_pressure.system_efficiency",
    "emla_battery_energy_J",
    "emla_cycle_battery_energy_J",
    "at_battery.*.cycle_battery_energy_J",
    "at_battery.*.emla_saving_percent",
    "emla_saving_vs_load_sensing_percent",
    "emla_saving_vs_constant_pressure_percent",
)
#: The fields of ``result.json`` the pages read (dotted paths, ``*`` for every key or item).
RESULT_FIELDS: tuple[str, ...] = (
    "name",
    "crane",
    *(f"{design}.{f}" for design in ("initial", "optimal") for f in _DESIGN),
    "improvement.net_energy_saved_J",
    "improvement.net_energy_saved_percent",
    "improvement.decomposition.from_lengths_J",
    "improvement.decomposition.from_trajectory_J",
    "solver.iterations",
    "solver.max_violation_scaled",
    "solver.total_wall_time_s",
    "recheck.id_path",
    "recheck.grid_points",
    "recheck.max_violation_scaled",
    "recheck.tracking_error.position_m",
    "recheck.force_difference_between_paths_N",
    "multistart.converged_starts",
    "multistart.same_optimum",
    "multistart.starts.*.iterations",
    "settings.payload_kg",
    "energy.objective",
    "energy.battery",
    "energy.drive_losses",
    "energy.duty",
    "energy.battery_energy_saved_percent",
    "energy.hourly_rms_torque_Nm",
    "energy.hourly_work_s",
    *(f"energy.{design}.{f}" for design in ("initial", "optimal") for f in _ENERGY),
    *(f"hydraulic_baseline.{design}.{f}" for design in ("initial", "optimal") for f in _HYDRAULIC),
    "codesign.rows.*.transmission",
    "codesign.rows.*.status",
    "codesign.rows.*.initial_battery_energy_J",
    "codesign.rows.*.battery_energy_J",
    "codesign.rows.*.lengths",
    "codesign.best",
    "codesign.reference",
    "codesign.mounting_only_saving_percent",
    "codesign.codesign_saving_percent",
    "codesign.extra_saving_J",
    "buildable.lengths",
    "buildable.tolerance_m",
    "buildable.stroke_margin_m",
    "buildable.range_given_up_deg",
    "buildable.tolerance_check.margin",
    "buildable.recheck.margin",
    "buildable.net_electrical_energy_J",
    "sensitivity.objective",
    "sensitivity.multipliers.*.constraint",
    "sensitivity.multipliers.*.unit",
    "sensitivity.multipliers.*.percent_per_unit",
    "tasks.*.name",
    "tasks.*.weight",
    "tasks.*.payload_kg",
    "tasks.*.duration_s",
    *(f"tasks.*.{design}.{f}" for design in ("initial", "optimal") for f in _DESIGN),
    "tasks.*.recheck.max_violation_scaled",
    "tasks.*.recheck.tracking_error.position_m",
    "tasks.*.energy.initial.battery_energy_J",
    "tasks.*.energy.optimal.battery_energy_J",
    "cross_evaluation.tasks",
    "cross_evaluation.designs",
    "cross_evaluation.net_energy_J",
    "cross_evaluation.mix_net_energy_J",
    "cross_evaluation.mix_energy_lost_J",
    "cross_evaluation.mix_energy_lost_percent",
    "cross_evaluation.mix_cost_lost_percent",
)
#: The fields of ``simulation.json`` (``hiab-sim simulate``) the pages read.
SIMULATION_FIELDS: tuple[str, ...] = (
    *(
        f"designs.*.{run}{f}"
        for run in ("", "nominal.")
        for f in (
            "payload_error",
            "net_electrical_energy_J",
            "predicted_net_electrical_energy_J",
            "energy_difference_percent",
            "tcp_error_mm.rms",
            "tcp_error_mm.max",
            "current_limit_fraction",
            "voltage_limit_fraction",
            "bandwidth_check.velocity_loop_bandwidth_Hz",
            "bandwidth_check.first_natural_frequency_Hz",
            "bandwidth_check.bandwidth_margin",
        )
    ),
    "designs.*.extra_energy_J",
)
#: The fields of ``energy_map.json`` (``hiab-sim energy-map``) the pages read.
ENERGY_MAP_FIELDS: tuple[str, ...] = (
    "variables",
    "base",
    "cells",
    "feasible_cells",
    "at_base.objective",
    "at_base.battery_energy_J",
    "best_feasible_cell.xi_m",
    "best_feasible_cell.objective",
    "best_feasible_cell.battery_energy_J",
    "infeasible_cells_by_binding_constraint",
)
#: The fields of ``pareto.json`` (``hiab-sim pareto``) the pages read.
PARETO_FIELDS: tuple[str, ...] = (
    "criterion",
    "unit",
    *(f"points.*.{k}" for k in ("epsilon", "criterion", "objective", "objective_unit", "accepted", "iterations")),
    "least_criterion.criterion",
    "least_criterion.objective",
)
#: The fields of a sweep's table (``hiab-sim sweep``: ``sweep.parquet``, one row per point) the pages read;
#: ``parameters`` holds each point's grid values by column name.
SWEEP_FIELDS: tuple[str, ...] = (
    "rows.*.parameters",
    *(
        f"rows.*.{k}"
        for k in (
            "status",
            "message",
            "iterations",
            "net_energy_saved_percent",
            "start_battery_energy_J",
            "opt_battery_energy_J",
            "start_net_energy_J",
            "opt_net_energy_J",
            *(f"opt_{c}_{k}_m" for c in CHAIN_NAMES for k in ("L", "Lc0", "Lc")),
        )
    ),
)

#: The fields of a model-effects table (``python -m hiab_sim.study.analysis.model_effects``) the pages read.
_EFFECT_ROW = ("key", "label", "emla", "hold", "compared_with", "status", "message", "iterations", "duty", "lengths")
_EFFECT_NUMBERS = ("initial_battery_energy_J", "battery_energy_J", "battery_energy_saved_percent")
MODEL_EFFECT_FIELDS = (
    "study",
    *(f"rows.*.{k}" for k in (*_EFFECT_ROW, *_EFFECT_NUMBERS, "peak_winding_temperature_C")),
)


def select(tree: Any, field: str) -> Any:
    """The part of ``tree`` a dotted field names, in the tree's own shape; None where the path is absent."""
    head, _, rest = field.partition(".")
    if head == "*":
        if isinstance(tree, list):
            items = [select(item, rest) if rest else item for item in tree]
            return items if any(i is not None for i in items) else None
        if isinstance(tree, dict):
            picked = {k: select(v, rest) if rest else v for k, v in tree.items()}
            picked = {k: v for k, v in picked.items() if v is not None}
            return picked or None
        return None
    if not isinstance(tree, dict) or head not in tree or tree[head] is None:
        return None
    inner = select(tree[head], rest) if rest else tree[head]
    return None if inner is None else {head: inner}


def merge(a: Any, b: Any) -> Any:
    """Two selections of one tree merged (objects key by key, lists item by item)."""
    if a is None:
        return b
    if b is None:
        return a
    if isinstance(a, dict) and isinstance(b, dict):
        return {k: merge(a.get(k), b.get(k)) for k in {**a, **b}}
    if isinstance(a, list) and isinstance(b, list):
        return [merge(x, y) for x, y in zip(a, b, strict=True)]
    return b


def pick(tree: Any, fields: tuple[str, ...]) -> dict[str, Any]:
    """The declared fields of a JSON tree, merged into one tree of the same shape."""
    out: Any = None
    for field in fields:
        out = merge(out, select(tree, field))
    return out or {}


def _sweep_rows(path: Path) -> dict[str, Any]:
    """A sweep table as ``{"rows": [...]}``: each row's result columns, its grid values under ``parameters``."""
    from hiab_sim.sweep.point import RUN_COLUMNS, VALUE_COLUMNS
    from hiab_sim.sweep.table import read_table

    frame, _ = read_table(path)
    # the result columns: the run's, the optimum's decision variables (opt_<chain>_<variable>_m), the values
    designs = [c for c in frame.columns if c.startswith("opt_") and c.endswith("_m") and c not in VALUE_COLUMNS]
    result_columns = (*RUN_COLUMNS, *designs, *VALUE_COLUMNS)
    rows = []
    for row in frame.to_dict("records"):
        clean = {k: None if isinstance(v, float) and math.isnan(v) else v for k, v in row.items()}
        parameters = {k: v for k, v in clean.items() if k != "key" and k not in result_columns}
        rows.append({**{k: clean[k] for k in result_columns}, "parameters": parameters})
    return {"rows": rows}


#: What a run folder may hold: section of the data -> (file in the folder, its reader, the declared fields).
SECTIONS: dict[str, tuple[str, Callable[[Path], Any], tuple[str, ...]]] = {
    "result": ("result.json", lambda path: read_result(path.parent).to_json(), RESULT_FIELDS),
    "simulation": ("simulation.json", parse_json, SIMULATION_FIELDS),
    "energy_map": ("energy_map.json", parse_json, ENERGY_MAP_FIELDS),
    "pareto": ("pareto.json", parse_json, PARETO_FIELDS),
    "sweep": ("sweep.parquet", _sweep_rows, SWEEP_FIELDS),
    "model_effects": ("model_effects.json", parse_json, MODEL_EFFECT_FIELDS),
}


def record(run_dir: Path) -> dict[str, Any]:
    """The data of one run folder: the declared fields of every file of :data:`SECTIONS` it holds.

    An ``optimize`` folder gives ``result`` (and ``simulation`` once ``hiab-sim simulate`` ran on it);
    an ``energy-map``, ``pareto``, ``sweep`` or model-effects folder its own section. A folder with none raises
    :class:`ValueError` naming the files looked for.
    """
    data = {}
    for section, (name, read, fields) in SECTIONS.items():
        if (run_dir / name).exists():
            data[section] = pick(read(run_dir / name), fields)
    if not data:
        files = ", ".join(name for name, _, _ in SECTIONS.values())
        raise ValueError(f"{run_dir}: no run output to record (looked for {files})")
    return data


def data_name(data: dict[str, Any], run_dir: Path) -> str:
    """The data file's name: an optimisation's study name, else the run folder's name."""
    return str(data["result"]["name"]) if "result" in data else run_dir.name


def write_data(data: dict[str, Any], name: str, data_dir: Path = DATA_DIR) -> Path:
    """Write one run's data to ``data_dir/<name>.json``; return the path."""
    path = data_dir / f"{name}.json"
    write_atomic(path, json.dumps(data, indent=1) + "\n")
    return path


def load_data(data_dir: Path = DATA_DIR) -> dict[str, dict[str, Any]]:
    """Every committed study's data, keyed by study name."""
    return {path.stem: parse_json(path) for path in sorted(data_dir.glob("*.json"))}


def _leaf_differs(path: str, got: Any, want: Any) -> bool:
    key = path.rsplit(".", 1)[-1]
    if key in NOT_COMPARED_KEYS:
        return False
    if isinstance(want, bool) or not isinstance(want, int | float) or isinstance(got, bool):
        return bool(got != want)
    if not isinstance(got, int | float):
        return True
    if key in ROUND_OFF_KEYS or path.endswith("buildable.recheck.margin"):
        if max(abs(got), abs(want)) <= ROUND_OFF_LIMIT:
            return False
    if key == "iterations":
        return abs(got - want) > max(1.0, ITERATION_TOLERANCE * abs(want))
    return not math.isclose(got, want, rel_tol=RELATIVE_TOLERANCE, abs_tol=ABSOLUTE_FLOOR)


def differences(got: Any, want: Any, path: str = "") -> list[str]:
    """Where ``got`` (fresh) differs from ``want`` (recorded) beyond the tolerances: one line per difference."""
    where = path or "(top)"
    if isinstance(want, dict) and isinstance(got, dict):
        if set(got) != set(want):
            return [f"{where}: keys {sorted(got)} != recorded {sorted(want)}"]
        return [d for k in sorted(want) for d in differences(got[k], want[k], f"{path}.{k}" if path else k)]
    if isinstance(want, list) and isinstance(got, list):
        if len(got) != len(want):
            return [f"{where}: {len(got)} items, recorded {len(want)}"]
        return [d for i, (g, w) in enumerate(zip(got, want, strict=True)) for d in differences(g, w, f"{path}.{i}")]
    if isinstance(want, dict | list) or isinstance(got, dict | list):
        return [f"{where}: {got!r} != recorded {want!r}"]
    return [f"{where}: {got!r}, recorded {want!r}"] if _leaf_differs(path, got, want) else []


class NotRecordedError(KeyError):
    """A page asks for a study that has no data file yet (its block says so on the page)."""

    def __init__(self, study: str) -> None:
        """``study``: the study's name."""
        super().__init__(f"no data for study {study!r}: record a run of it (docs/results/data/{study}.json)")
        self.study = study


class RunData:
    """The committed data of every study, read by dotted path: ``runs("xs031_spiral", "result.solver.iterations")``."""

    def __init__(self, data: dict[str, dict[str, Any]]) -> None:
        """``data``: study name -> its data (:func:`load_data`)."""
        self._data = data

    def __call__(self, study: str, path: str) -> Any:
        """The value at ``path`` of ``study``'s data; KeyError naming the file and the path when it is absent."""
        if study not in self._data:
            raise NotRecordedError(study)
        node: Any = self._data[study]
        for step in path.split("."):
            if isinstance(node, list) and step.isdigit() and int(step) < len(node):
                node = node[int(step)]
            elif isinstance(node, dict) and step in node:
                node = node[step]
            else:
                raise KeyError(f"docs/results/data/{study}.json has no {path!r} (is it in RESULT_FIELDS?)")
        return node

    def section(self, study: str, section: str) -> Callable[[str], Any]:
        """A reader of one section of ``study``'s data (a key of :data:`SECTIONS`)."""
        return lambda path: self(study, f"{section}.{path}")

    def result(self, study: str) -> Callable[[str], Any]:
        """A reader of ``study``'s ``result.json`` fields: ``runs.result("xs031_spiral")("solver.iterations")``."""
        return self.section(study, "result")

    def simulation(self, study: str) -> Callable[[str], Any]:
        """A reader of ``study``'s ``simulation.json`` fields."""
        return self.section(study, "simulation")

    def has(self, study: str, path: str) -> bool:
        """Whether ``study``'s data have ``path``."""
        try:
            self(study, path)
        except KeyError:
            return False
        return True

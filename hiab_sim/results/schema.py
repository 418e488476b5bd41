"""Typed result of an optimisation run: the frozen dataclasses behind ``result.json``.

Every key ``result.json`` had before it was typed is kept under its name (users read those
names), and ``schema_version`` is written on top. Energies in [J], costs of eq. ``costf2`` in
[W^2 s] (a squared-power integral, not an energy), lengths in [m], times in [s]; "scaled" values
are the NLP's O(1) units. Link lengths are :class:`~hiab_sim.config.LinkLengths`, written as
``{"lift": {"L", "Lc0", "Lc"}, "tilt": {...}}``.

Extending the format: a new section is a field ``name: Section | None = optional()`` (added at the
end of its dataclass), so files written before it still load (the field is None) and results
without it do not write the key. ``schema_version`` changes only when a key is removed, renamed
or changes its meaning; a reader refuses files of a newer schema. Unknown top-level keys are kept
in :attr:`Result.extra` and written back.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar, cast

from hiab_sim.errors import ConfigError
from hiab_sim.results.analysis_sections import Buildable, CrossEvaluation, FeasibilityPhase, Sensitivity
from hiab_sim.results.codec import from_json, optional, to_json
from hiab_sim.results.design_values import DesignValues
from hiab_sim.results.energy_sections import Codesign, EnergyReport, HydraulicBaseline
from hiab_sim.results.multistart import MultiStart
from hiab_sim.results.playback_view import PlaybackView as PlaybackView  # re-exported: the renderer's contract
from hiab_sim.structure.summary import StructureSummary

#: Version of the result.json layout; files without the key are version 1. Version 2 renames the
#: ``sensitivity`` keys that held the objective's value whatever its unit (``cost_W2s`` ->
#: ``objective_value`` with ``objective`` and ``objective_unit``, ``multipliers[].cost_per_unit_W2s``
#: -> ``objective_decrease_per_unit``) and the energy keys whose names suggested another boundary
#: (:data:`RENAMED_IN_2`); :func:`upgrade` reads every older file.
SCHEMA_VERSION = 2
#: The unit of each objective a version-1 file can name (the objectives that existed then).
_SCHEMA1_UNITS = {"costf2": "W^2 s", "battery_energy": "J"}
#: Energy keys renamed in schema 2 because their names suggested another boundary (old -> new).
RENAMED_IN_2: dict[str, str] = {
    "drawn_energy_without_regeneration_J": "drawn_energy_summed_drives_J",
    "drawn_energy_sum_of_actuators_J": "drawn_energy_per_drive_sum_J",
}
RESULT_FILE = "result.json"
#: Keys of :class:`EnergyBreakdown`, in the order the figures and tables show them.
T = TypeVar("T")
ENERGY_PARTS = ("mechanical", "copper", "rotor_friction", "screw_viscous", "inertial", "electrical")


@dataclass(frozen=True)
class EnergyBreakdown:
    """Energy over the motion by power flow (:func:`hiab_sim.emla.operating_point`) [J], summed over the drives.

    At the reference (cold) winding resistance: the hot windings' extra copper loss is the duty's
    ``hot_winding_extra_J``. electrical = mechanical + copper + rotor_friction + screw_viscous +
    inertial + the drive train's losses (screw and gearbox efficiency, inverter, brake coil), which
    no field here names: they are electrical minus the sum of the five parts (zero on the paper model).
    """

    mechanical: float
    copper: float
    rotor_friction: float
    screw_viscous: float
    inertial: float
    electrical: float

    def as_tuple(self) -> tuple[float, ...]:
        """The six energies in :data:`ENERGY_PARTS` order [J]."""
        return tuple(getattr(self, k) for k in ENERGY_PARTS)


@dataclass(frozen=True)
class ActuatorSummary:
    """One actuator over the motion: peaks, envelope margin, energies."""

    peak_force_N: float
    peak_velocity_m_per_s: float
    peak_electrical_power_W: float
    min_envelope_margin: float  # scaled, >= 0 inside the envelope
    net_energy_J: float
    drawn_energy_J: float
    energy_J: EnergyBreakdown


@dataclass(frozen=True)
class WorstConstraint:
    """The constraint row or design-variable bound (``bound lift.L up = 1.25 m``) with the smallest scaled margin."""

    name: str
    scaled_margin: float


@dataclass(frozen=True)
class TrackingError:
    """Largest deviation from the reference over the grid: TCP in the plane, and each further tracked coordinate.

    ``telescope_m``: the crane's telescope extension xt2 [m] (None for a machine file, whose further
    tracked coordinates are in ``tracked``, keyed ``<name>_<unit>``, e.g. ``tcp_angle_rad``).
    """

    position_m: float
    velocity_m_per_s: float
    acceleration_m_per_s2: float
    telescope_m: float | None
    tracked: dict[str, float] | None = optional()


@dataclass(frozen=True)
class DesignSummary:
    """One design (link lengths and trajectory) evaluated on a grid by one ID path.

    ``collocation_cost_W2s`` and ``collocation_max_violation`` are set on the result's initial and
    optimal designs (the optimiser's grid), not on the other fine-grid checks.

    ``net_electrical_energy_J``, the drawn energies and each actuator's ``net_energy_J`` and ``drawn_energy_J``
    integrate the optimiser's drive powers at the drives' DC inputs: smooth drive losses and, with the study's
    duty model, the windings at their periodic fixed-point temperature (hot). ``energy_breakdown_J`` and each
    actuator's ``energy_J`` are exact at the cold resistance (:class:`EnergyBreakdown`): their ``electrical``
    differs from ``net_electrical_energy_J`` by the hot windings' copper and the smoothing. The battery's
    energy is the ``energy`` section's.
    """

    lengths: DesignValues
    id_path: str
    grid_points: int
    cost_W2s: float
    cost_note: str
    net_electrical_energy_J: float
    # int max(sum_i P_i, 0) dt: the drives' powers summed before the positive part is taken, so one drive's
    # regeneration feeds another (the shared bus seen at the drives' inputs; no inverter or battery)
    drawn_energy_summed_drives_J: float
    # sum_i int max(P_i, 0) dt: every drive's own positive power, no credit passed between drives
    drawn_energy_per_drive_sum_J: float
    energy_breakdown_J: EnergyBreakdown
    actuators: dict[str, ActuatorSummary]
    max_violation: float
    worst_constraint: WorstConstraint
    tracking_error: TrackingError
    collocation_cost_W2s: float | None = optional()
    collocation_max_violation: float | None = optional()


@dataclass(frozen=True)
class DecompositionDesign:
    """One (lengths from, trajectory from) combination of the decomposition; mixed designs may fail to evaluate."""

    lengths: str  # "initial" or "optimal"
    trajectory: str  # "initial" or "optimal"
    evaluable: bool
    error: str | None = optional()
    net_electrical_energy_J: float | None = optional()
    drawn_energy_summed_drives_J: float | None = optional()
    cost_W2s: float | None = optional()
    collocation_cost_W2s: float | None = optional()
    max_violation: float | None = optional()
    worst_constraint: WorstConstraint | None = optional()


@dataclass(frozen=True)
class Decomposition:
    """The saving split into the lengths' and the trajectory's parts.

    See :func:`~hiab_sim.study.report.result_folder.energy_decomposition`. Savings are relative to the initial
    design [J, %]; None where a mixed design is not evaluable.
    """

    note: str
    designs: dict[str, DecompositionDesign]
    from_lengths_J: float | None
    from_lengths_percent: float | None
    from_trajectory_J: float | None
    from_trajectory_percent: float | None
    interaction_J: float | None
    total_J: float | None


@dataclass(frozen=True)
class Improvement:
    """Optimal vs initial design: collocation cost ratio and fine-grid net-energy saving."""

    cost_ratio: float
    net_energy_saved_J: float
    net_energy_saved_percent: float
    decomposition: Decomposition


@dataclass(frozen=True)
class SolverSummary:
    """The SQP run of the study's own start."""

    method: str
    id_path: str
    success: bool
    status: int
    message: str
    iterations: int
    wall_time_s: float
    total_wall_time_s: float
    max_violation_scaled: float
    function_evaluations: int
    gradient_evaluations: int


@dataclass(frozen=True)
class Recheck:
    """The optimum re-evaluated on the fine grid with the other ID path and nominal bands."""

    id_path: str
    grid_points: int
    note: str
    max_violation_scaled: float
    worst_constraint: WorstConstraint
    tracking_error: TrackingError
    net_electrical_energy_J: float
    initial_max_violation_scaled: float
    force_difference_between_paths_N: float


@dataclass(frozen=True)
class TrackingBands:
    """The study's nominal tracking bands and the fraction of them held at the collocation points."""

    position_m: float
    velocity_m_per_s: float
    acceleration_m_per_s2: float
    collocation_fraction: float


@dataclass(frozen=True)
class Settings:
    """Discretisation, bounds and load of the run."""

    spline_control_points: int
    spline_degree: int
    collocation_points: int
    collocation_step_s: float
    fine_grid_points: int
    redundancy: str
    tracking_bands: TrackingBands
    xi_low: tuple[float, ...]
    xi_up: tuple[float, ...]
    envelope_margin: float
    payload_kg: float


@dataclass(frozen=True)
class HistoryRow:
    """One SQP iteration: cost [W^2 s], scaled cost, max violation (scaled), Xi [m], wall time [s]."""

    iteration: int
    cost: float
    scaled_cost: float
    max_violation: float
    xi: tuple[float, ...]
    wall_time: float


@dataclass(frozen=True)
class TaskResult:
    """One task of a duty mix (or of a study of one task of weight other than 1): share, load, grid, designs, re-check.

    Written by :func:`hiab_sim.study.report.result_folder.build_result`.

    ``telescope`` says how the crane's redundancy is set for the task (prescribed by the reference); None
    (absent) for a machine file's study, which has no telescope (its tracked coordinates are the
    reference's columns; each one's error is in ``tracking_error.tracked``). Files before this rule
    hold the crane's text for a machine file too.
    """

    name: str
    weight: float
    kind: str
    duration_s: float
    payload_kg: float
    spline_control_points: int
    collocation_points: int
    initial: DesignSummary
    optimal: DesignSummary
    recheck: Recheck
    telescope: str | None = optional()  # the crane's telescope: how the reference sets it; None on a machine file
    energy: EnergyReport | None = optional()  # battery energy, costf2, thermal at the study's duty
    structure: StructureSummary | None = optional()  # the task's own pin loads, buckling, natural frequencies


@dataclass(frozen=True)
class Result:
    """What ``hiab-sim optimize`` writes to ``result.json``.

    ``crane`` is the preset name, or ``crane.yaml`` (a copy in the result folder) when the study
    gave a file, then named in ``crane_source``; ``study`` is the study file's absolute path (a
    shipped study's file in the package).
    """

    crane: str
    study: str
    name: str
    initial: DesignSummary
    optimal: DesignSummary
    improvement: Improvement
    solver: SolverSummary
    recheck: Recheck
    multistart: MultiStart
    settings: Settings
    history: tuple[HistoryRow, ...]
    schema_version: int = SCHEMA_VERSION
    crane_source: str | None = optional()
    energy: EnergyReport | None = optional()  # battery energy and costf2, thermal
    hydraulic_baseline: HydraulicBaseline | None = optional()
    codesign: Codesign | None = optional()
    # each task's own cycle: a duty mix, or one task of weight w != 1 (the top level then being w times it)
    tasks: tuple[TaskResult, ...] | None = optional()
    cross_evaluation: CrossEvaluation | None = optional()
    buildable: Buildable | None = optional()
    feasibility: tuple[FeasibilityPhase, ...] | None = optional()
    sensitivity: Sensitivity | None = optional()
    structure: StructureSummary | None = optional()  # pin loads, buckling, frequencies (a mix: over its tasks)
    extra: dict[str, Any] = field(default_factory=dict)  # keys of a newer writer, kept verbatim

    def __post_init__(self) -> None:
        if self.schema_version > SCHEMA_VERSION:
            raise ConfigError(
                f"result.json has schema_version {self.schema_version}; this hiab-sim reads up to {SCHEMA_VERSION}"
            )

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dict (``schema_version`` first)."""
        data = to_json(self)
        return {"schema_version": data.pop("schema_version"), **data}

    @classmethod
    def from_json(cls, data: Any) -> Result:
        """Build from a parsed result.json of any version up to :data:`SCHEMA_VERSION` (:func:`upgrade`).

        ConfigError names a missing or mistyped key.
        """
        return from_json(cls, upgrade(data))


def upgrade(data: Any) -> Any:
    """A parsed result.json of an older layout with its renamed keys under their version-2 names.

    The energy keys of :data:`RENAMED_IN_2` take their new names at any depth. Version 1 stored the
    objective's value as ``sensitivity.cost_W2s`` and the decreases as
    ``cost_per_unit_W2s`` whatever the objective (joules under ``battery_energy``); the objective
    is the file's ``energy.objective`` (``costf2`` without an energy section).
    """
    if not isinstance(data, dict):
        return data
    version = data.get("schema_version", 1)  # a file without the key is version 1
    if isinstance(version, int) and version > SCHEMA_VERSION:
        raise ConfigError(f"result.json has schema_version {version}; this hiab-sim reads up to {SCHEMA_VERSION}")
    # Files written between the two renamings say version 2 with either set of old names: each
    # renaming is applied where its old keys are present, so every such file reads.
    data = {**_renamed(data), "schema_version": max(2, version) if isinstance(version, int) else version}
    old = data.get("sensitivity")
    if not isinstance(old, dict) or "cost_W2s" not in old:
        return data
    energy = data.get("energy")
    objective = energy.get("objective", "costf2") if isinstance(energy, dict) else "costf2"
    sensitivity = {k: v for k, v in old.items() if k != "cost_W2s"}
    sensitivity = {
        "objective": objective,
        "objective_unit": _SCHEMA1_UNITS.get(objective, "unknown"),
        "objective_value": old["cost_W2s"],
        **sensitivity,
    }
    sensitivity["multipliers"] = [
        {("objective_decrease_per_unit" if k == "cost_per_unit_W2s" else k): v for k, v in m.items()}
        for m in old.get("multipliers", [])
    ]
    return {**data, "sensitivity": sensitivity}


def _renamed(data: Any) -> Any:
    """``data`` with the keys of :data:`RENAMED_IN_2` renamed, at any depth."""
    if isinstance(data, dict):
        return {RENAMED_IN_2.get(k, k): _renamed(v) for k, v in data.items()}
    if isinstance(data, list):
        return [_renamed(v) for v in data]
    return data


def parse_json(path: Path) -> Any:
    """Parsed JSON of ``path``; ConfigError when it cannot be read or is not JSON."""
    try:
        return json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ConfigError(f"{path}: not valid JSON: {error}") from None


def read_json_as(cls: type[T], path: Path) -> T:
    """``cls`` built from the JSON file ``path``; ConfigError names the file and the bad key."""
    data = parse_json(path)
    try:
        if cls is Result:  # every version it reads (upgrade)
            return cast(T, Result.from_json(data))
        return from_json(cls, data)
    except ConfigError as error:
        raise ConfigError(f"{path}: {error}") from None

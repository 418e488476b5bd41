"""The optimiser's plan for one design, read from a result folder.

:func:`open_design` reads one design of any result folder (``result.json`` and ``trajectory.npz``)
into the fields every plan has (:class:`PlannedDesign`); a crane file's plan (:class:`DesignPlan`)
and a machine file's (:class:`hiab_sim.env.machine_plan.MachinePlan`) add their own.
``read_plan(result_dir, design)`` returns what the closed-loop validation needs: the crane, the EMLA
set and the payload of the study, the design's link lengths, its planned joint trajectory
(positions, rates, accelerations on the fine grid), the study's TCP reference and the optimiser's
predicted net electrical energy, through the one result-folder reader
(:func:`hiab_sim.results.read.open_run`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.emla.config import EmlaSet, load_emla_set
from hiab_sim.emla.duty_energy import DutyOptions
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.results.read import DESIGNS, RunFolder, open_run, result_crane
from hiab_sim.results.schema import DesignSummary, Result
from hiab_sim.study.spec.study_file import load_study

Array = NDArray[np.float64]


@dataclass(frozen=True)
class PlannedDesign:
    """What the closed loop needs of any design's plan, a crane file's or a machine file's.

    Attributes:
        design: ``initial`` or ``optimal``.
        emlas: The EMLA set the study used, one per actuator in the model's order.
        time: Fine-grid sample times [s], (K,), from 0 to the cycle duration.
        position, velocity, acceleration: Planned independent joints and their rates, (K, J)
            [rad or m; per s; per s^2] (the crane's Θ1, Θ2, xt2).
        reference_tcp: The study's TCP reference (x_tcp, y_tcp, z_tcp) in the source frame {W}, (K, 3) [m]:
            the path in the machine's plane at the TCP's out-of-plane coordinate z_tcp.
        predicted_electrical_power: Planned P_elec per actuator, (K, A) [W].
        predicted_net_energy: The optimiser's net electrical energy of the design [J].

    """

    design: str
    emlas: EmlaSet
    time: Array
    position: Array
    velocity: Array
    acceleration: Array
    reference_tcp: Array
    predicted_electrical_power: Array
    predicted_net_energy: float

    @property
    def duration(self) -> float:
        """Cycle duration [s]."""
        return float(self.time[-1] - self.time[0])


@dataclass(frozen=True)
class DesignPlan(PlannedDesign):
    """One design of a crane file's result (the fields of :class:`PlannedDesign` and the crane's).

    Attributes:
        crane: The crane description.
        lengths: The design's link lengths Xi [m].
        payload: Mass hanging at the TCP in the study [kg].
        duty: The study's duty model of the cycle (hot windings, the rest's hold), or None: the
            paper's per-sample model (:func:`hiab_sim.study.nlp.task_setup.duty_options`).

    """

    crane: Crane
    lengths: LinkLengths
    payload: float
    duty: DutyOptions | None = None


@dataclass(frozen=True)
class DesignRun:
    """One design of a result folder, read once for every kind of plan.

    Attributes:
        run: The folder as :func:`hiab_sim.results.read.open_run` read it.
        summary: The design's summary in ``result.json``.
        planned: The design's planned fields (:class:`PlannedDesign`'s, all but ``emlas``) from ``trajectory.npz``.

    """

    run: RunFolder[Result]
    summary: DesignSummary
    planned: dict[str, Any]


def open_design(result_dir: str | Path, design: str) -> DesignRun:
    """Read ``result.json`` and ``trajectory.npz`` of an ``hiab-sim optimize`` folder for one design.

    Raises:
        InvalidInputError: unknown design.
        ConfigError: the folder holds no result, or its files are malformed (one line naming them).

    """
    if design not in DESIGNS:
        raise InvalidInputError("design", design, f"must be one of {', '.join(DESIGNS)}")
    run = open_run(result_dir, Result)
    trajectory = run.trajectory
    summary = run.result.optimal if design == "optimal" else run.result.initial
    planned = {
        "design": design,
        "time": trajectory.time(),
        "position": trajectory.design(design, "position"),
        "velocity": trajectory.design(design, "velocity"),
        "acceleration": trajectory.design(design, "acceleration"),
        "reference_tcp": trajectory.get("reference_tcp"),
        "predicted_electrical_power": trajectory.design(design, "electrical_power"),
        "predicted_net_energy": float(summary.net_electrical_energy_J),
    }
    return DesignRun(run, summary, planned)


def read_plan(result_dir: str | Path, design: str) -> DesignPlan:
    """The plan of one design of a crane file's result (:func:`open_design`, the study's crane and EMLA set).

    Raises:
        InvalidInputError: unknown design.
        ConfigError: the folder holds no result, or its files are malformed (one line naming them).

    """
    found = open_design(result_dir, design)
    result = found.run.result
    emlas, duty = _study_emlas(result.study, found.planned["time"])
    return DesignPlan(
        **found.planned,
        crane=result_crane(found.run.folder, result.crane),
        emlas=emlas,
        lengths=crane_lengths(found.summary.lengths, "result"),
        payload=float(result.settings.payload_kg),
        duty=duty,
    )


def _study_emlas(study: str, time: Array) -> tuple[EmlaSet, DutyOptions | None]:
    """The study's EMLA set and duty model for a cycle on ``time`` [s] (the preset and none when the file is gone)."""
    from hiab_sim.study.nlp.task_setup import duty_options

    try:
        spec = load_study(study)
    except ConfigError:
        return load_emla_set(None), None
    return spec.emlas, duty_options(spec, spec.emlas, float(time[-1] - time[0]))

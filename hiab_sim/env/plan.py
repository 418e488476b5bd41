"""The optimiser's plan for one design, read from a result folder.

``read_plan(result_dir, design)`` returns what the closed-loop validation needs: the crane, the EMLA
set and the payload of the study, the design's link lengths, its planned joint trajectory
(positions, rates, accelerations on the fine grid), the study's TCP reference and the optimiser's
predicted net electrical energy, through the one result-folder reader
(:func:`hiab_sim.results.read.open_run`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.emla.config import EmlaSet, load_emla_set
from hiab_sim.emla.duty_energy import DutyOptions
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.results.read import open_run, result_crane
from hiab_sim.results.schema import Result
from hiab_sim.study.spec.study_file import load_study

Array = NDArray[np.float64]

#: Designs a result holds.
DESIGNS: tuple[str, ...] = ("initial", "optimal")


@dataclass(frozen=True)
class DesignPlan:
    """One design of a study result.

    Attributes:
        design: ``initial`` or ``optimal``.
        crane: The crane description.
        emlas: The EMLA set the study used.
        lengths: The design's link lengths Xi [m].
        time: Fine-grid sample times [s], (K,), from 0 to the cycle duration.
        position, velocity, acceleration: Planned (Θ1, Θ2, xt2) and their rates, (K, 3) [rad, m].
        reference_tcp: The study's TCP reference in the source frame {W}, (K, 3) [m].
        predicted_electrical_power: Planned P_elec per actuator, (K, 3) [W].
        predicted_net_energy: The optimiser's net electrical energy of the design [J].
        payload: Mass hanging at the TCP in the study [kg].
        duty: The study's duty model of the cycle (hot windings, the rest's hold), or None: the
            paper's per-sample model (:func:`hiab_sim.study.nlp.task_setup.duty_options`).

    """

    design: str
    crane: Crane
    emlas: EmlaSet
    lengths: LinkLengths
    time: Array
    position: Array
    velocity: Array
    acceleration: Array
    reference_tcp: Array
    predicted_electrical_power: Array
    predicted_net_energy: float
    payload: float
    duty: DutyOptions | None = None

    @property
    def duration(self) -> float:
        """Cycle duration [s]."""
        return float(self.time[-1] - self.time[0])


def read_plan(result_dir: str | Path, design: str) -> DesignPlan:
    """Read ``result.json`` and ``trajectory.npz`` of an ``hiab-sim optimize`` folder for one design.

    Raises:
        InvalidInputError: unknown design.
        ConfigError: the folder holds no result, or its files are malformed (one line naming them).

    """
    if design not in DESIGNS:
        raise InvalidInputError("design", design, f"must be one of {', '.join(DESIGNS)}")
    run = open_run(result_dir, Result)
    result, trajectory = run.result, run.trajectory
    summary = result.optimal if design == "optimal" else result.initial
    emlas, duty = _study_emlas(result.study, trajectory.time())
    return DesignPlan(
        design=design,
        crane=result_crane(run.folder, result.crane),
        emlas=emlas,
        lengths=crane_lengths(summary.lengths, "result"),
        time=trajectory.time(),
        position=trajectory.design(design, "position"),
        velocity=trajectory.design(design, "velocity"),
        acceleration=trajectory.design(design, "acceleration"),
        reference_tcp=trajectory.get("reference_tcp"),
        predicted_electrical_power=trajectory.design(design, "electrical_power"),
        predicted_net_energy=float(summary.net_electrical_energy_J),
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

"""The optimiser's plan for one design, read from a result folder: the one place that reads result files.

``read_plan(result_dir, design)`` returns what the closed-loop validation needs: the crane, the EMLA
set and the payload of the study, the design's link lengths, its planned joint trajectory
(positions, rates, accelerations on the fine grid), the study's TCP reference and the optimiser's
predicted net electrical energy. When the study results become typed (``hiab_sim.results.schema``),
only this function changes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.emla.config import EmlaSet, load_emla_set
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.results.read import result_crane
from hiab_sim.results.schema import read_result
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

    @property
    def duration(self) -> float:
        """Cycle duration [s]."""
        return float(self.time[-1] - self.time[0])


def read_plan(result_dir: str | Path, design: str) -> DesignPlan:
    """Read ``result.json`` and ``trajectory.npz`` of an ``hiab-sim optimize`` folder for one design.

    Raises:
        InvalidInputError: unknown design, or the folder holds no result.
        ConfigError: the files are malformed.

    """
    if design not in DESIGNS:
        raise InvalidInputError("design", design, f"must be one of {', '.join(DESIGNS)}")
    folder = Path(result_dir)
    result_file, arrays_file = folder / "result.json", folder / "trajectory.npz"
    if not (result_file.is_file() and arrays_file.is_file()):
        raise InvalidInputError(
            "RESULT_DIR", str(folder), "must hold result.json and trajectory.npz of hiab-sim optimize"
        )
    result = read_result(folder)
    summary = result.optimal if design == "optimal" else result.initial
    crane = result_crane(folder, result.crane)
    try:
        arrays = dict(np.load(arrays_file))
        return DesignPlan(
            design=design,
            crane=crane,
            emlas=_study_emlas(result.study),
            lengths=summary.lengths,
            time=np.asarray(arrays["time"], dtype=float),
            position=np.asarray(arrays[f"{design}_position"], dtype=float),
            velocity=np.asarray(arrays[f"{design}_velocity"], dtype=float),
            acceleration=np.asarray(arrays[f"{design}_acceleration"], dtype=float),
            reference_tcp=np.asarray(arrays["reference_tcp"], dtype=float),
            predicted_electrical_power=np.asarray(arrays[f"{design}_electrical_power"], dtype=float),
            predicted_net_energy=float(summary.net_electrical_energy_J),
            payload=float(result.settings.payload_kg),
        )
    except (KeyError, ValueError, TypeError, OSError) as error:
        raise ConfigError(f"{folder}: not a readable hiab-sim optimize result ({error})") from None


def _study_emlas(study: str) -> EmlaSet:
    """The study's EMLA set (the preset when the study file is gone)."""
    try:
        return load_study(study).emlas
    except ConfigError:
        return load_emla_set(None)

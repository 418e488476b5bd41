"""The optimiser's plan for one design of a machine file's result (:mod:`hiab_sim.machine`).

``read_machine_plan(result_dir, design)`` returns what the closed loop of
:mod:`hiab_sim.env.machine_env` needs, through the one result-folder reader
(:func:`hiab_sim.results.read.open_run`): the machine built to the design's values
(:class:`~hiab_sim.machine.design.MachineDesign`, :func:`hiab_sim.results.read.result_machine`),
the study's EMLA set in chain order, the planned independent-joint trajectory on the fine grid, the
study's reference, the predicted P_elec per drive and net electrical energy, and the study's TCP
force F(t) of its first task (:meth:`hiab_sim.study.spec.tasks.Task.id_force`: the payload's
weight, a scheduled or inertial payload, soil), the same force the optimiser's inverse dynamics
took, so that the ideal plant is the planner's own model.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiab_sim.emla.config import EmlaSet
from hiab_sim.env.plan import DESIGNS
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import MachineDesign
from hiab_sim.results.read import open_run, result_machine
from hiab_sim.results.schema import Result
from hiab_sim.study.spec.study_file import load_study

Array = NDArray[np.float64]


@dataclass(frozen=True)
class MachinePlan:
    """One design of a machine file's result.

    Attributes:
        design: ``initial`` or ``optimal``.
        machine: The machine with the design's decision variables set.
        emlas: The study's EMLA set, one per chain in chain order.
        time: Fine-grid sample times [s], (K,).
        position, velocity, acceleration: Planned independent joints (machine joint order), (K, J) [rad or m].
        reference_tcp: The study's reference (x_tcp, y_tcp, extra tracked) in {W}, (K, 3) [m, m, rad or m].
        predicted_electrical_power: Planned P_elec per drive, (K, A) [W].
        predicted_net_energy: The optimiser's net electrical energy of the design [J].
        tcp_force: The force on the TCP the plan's inverse dynamics took, (K, 3) [N] in {W}.

    """

    design: str
    machine: Machine
    emlas: EmlaSet
    time: Array
    position: Array
    velocity: Array
    acceleration: Array
    reference_tcp: Array
    predicted_electrical_power: Array
    predicted_net_energy: float
    tcp_force: Array

    @property
    def duration(self) -> float:
        """Cycle duration [s]."""
        return float(self.time[-1] - self.time[0])

    @property
    def actuator_names(self) -> tuple[str, ...]:
        """The EMLA names, in chain order."""
        return self.emlas.names


def is_machine_result(result_dir: str | Path) -> bool:
    """Whether a result folder is a machine file's (its designs are :class:`MachineDesign`)."""
    return isinstance(open_run(result_dir, Result).result.optimal.lengths, MachineDesign)


def read_machine_plan(result_dir: str | Path, design: str) -> MachinePlan:
    """Read ``result.json``, ``trajectory.npz`` and the study file of a machine file's result for one design.

    Raises:
        InvalidInputError: unknown design, or a crane file's result.
        ConfigError: the folder holds no result, its files are malformed, or the study file is gone
            (its EMLA set and TCP force are needed; one line naming it).

    """
    if design not in DESIGNS:
        raise InvalidInputError("design", design, f"must be one of {', '.join(DESIGNS)}")
    run = open_run(result_dir, Result)
    result, trajectory = run.result, run.trajectory
    summary = result.optimal if design == "optimal" else result.initial
    values = summary.lengths
    if not isinstance(values, MachineDesign):
        raise InvalidInputError("result", str(result_dir), "is a crane file's result (read it with read_plan)")
    machine = result_machine(run.folder, result).with_design(values.values, check_bounds=False)
    try:
        study = load_study(result.study)
    except ConfigError as error:
        raise ConfigError(
            f"{run.folder}: the study file {result.study} is needed for its EMLA set and TCP force ({error})"
        ) from error
    time = trajectory.time()
    task = study.tasks[0]
    force = task.id_force(study.model.kinematics, study.model.gravity, time)
    tcp_force = np.zeros((len(time), 3)) if force is None else np.broadcast_to(force, (len(time), 3)).copy()
    return MachinePlan(
        design=design,
        machine=machine,
        emlas=study.emlas,
        time=time,
        position=trajectory.design(design, "position"),
        velocity=trajectory.design(design, "velocity"),
        acceleration=trajectory.design(design, "acceleration"),
        reference_tcp=trajectory.get("reference_tcp"),
        predicted_electrical_power=trajectory.design(design, "electrical_power"),
        predicted_net_energy=float(summary.net_electrical_energy_J),
        tcp_force=np.asarray(tcp_force, dtype=float),
    )

"""The optimiser's plan for one design (and task of a duty mix) of a machine file's result (:mod:`hiab_sim.machine`).

``read_machine_plan(result_dir, design, task)`` returns what the closed loop of
:mod:`hiab_sim.env.machine_env` needs, through the one result-folder reader
(:func:`hiab_sim.results.read.open_run`): the machine built to the design's values
(:class:`~hiab_sim.machine.design.MachineDesign`, :func:`hiab_sim.results.read.result_machine`),
the study's EMLA set in chain order, the planned independent-joint trajectory on the fine grid, the
study's reference, the predicted P_elec per drive and net electrical energy, and the TCP force F(t)
of the task (:meth:`hiab_sim.study.spec.tasks.Task.id_force`: the payload's weight, a scheduled or
inertial payload, soil), the same force the optimiser's inverse dynamics took, so that the ideal
plant is the planner's own model, and the payload's share of it (F(t) less the soil's force: what a
payload mismatch scales, :mod:`hiab_sim.env.plant.mismatch`), and the study's duty model of the
task's cycle (hot windings, the rest's hold), as a crane file's plan has it. A duty mix's result is
read per task (:func:`hiab_sim.env.plan.open_design`): its motion, energies, payload and duty are the
task's own.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla.duty_energy import DutyOptions
from hiab_sim.env.plan import PlannedDesign, open_design, studied_task
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import MachineDesign
from hiab_sim.results.read import open_run, result_machine
from hiab_sim.results.schema import Result


@dataclass(frozen=True)
class MachinePlan(PlannedDesign):
    """One design of a machine file's result (the fields of :class:`~hiab_sim.env.plan.PlannedDesign` and these).

    ``emlas`` is the study's EMLA set, one per chain in chain order; ``position``, ``velocity`` and
    ``acceleration`` are the independent joints in the machine's joint order, (K, J) [rad or m];
    ``reference_tcp`` is (x_tcp, y_tcp, z_tcp) in {W}, (K, 3) [m], z_tcp the TCP's out-of-plane coordinate;
    ``predicted_electrical_power`` is per drive, (K, A) [W].

    Attributes:
        machine: The machine with the design's decision variables set.
        tcp_force: The force on the TCP the plan's inverse dynamics took, (K, 3) [N] in {W}.
        payload_kg: The task's payload mass [kg], held at the TCP for the natural frequencies
            (its weight is in ``tcp_force``).
        tracked: The study's tracked coordinates beyond the TCP's x, y (the payload's kinematics), or
            None: ``tcp_angle`` for each.
        payload_force: The payload's share of ``tcp_force`` (without the soil's), (K, 3) [N] in {W}.
        duty: The study's duty model of the cycle, or None: the paper's per-sample model
            (:func:`hiab_sim.study.nlp.task_setup.duty_options`).

    """

    machine: Machine
    tcp_force: Array
    payload_force: Array
    payload_kg: float = 0.0
    tracked: tuple[str, ...] | None = None
    duty: DutyOptions | None = None

    @property
    def actuator_names(self) -> tuple[str, ...]:
        """The EMLA names, in chain order."""
        return self.emlas.names


def is_machine_result(result_dir: str | Path) -> bool:
    """Whether a result folder is a machine file's (its designs are :class:`MachineDesign`)."""
    return isinstance(open_run(result_dir, Result).result.optimal.lengths, MachineDesign)


def read_machine_plan(result_dir: str | Path, design: str, task: int | None = None) -> MachinePlan:
    """Read ``result.json``, ``trajectory.npz`` and the study file of a machine file's result for one design.

    ``task`` is the index k of a duty mix's task, None for a single-task result.

    Raises:
        InvalidInputError: unknown design, a task index out of range (none for a duty mix), or a
            crane file's result.
        ConfigError: the folder holds no result, its files are malformed, or the study file is gone
            (its EMLA set and TCP force are needed) or no longer holds the result's tasks
            (:func:`hiab_sim.env.plan.result_study`; one line naming it).

    """
    found = open_design(result_dir, design, task)
    run, values = found.run, found.summary.lengths
    if not isinstance(values, MachineDesign):
        raise InvalidInputError("result", str(result_dir), "is a crane file's result (read it with read_plan)")
    result = run.result
    machine = result_machine(run.folder, result).with_design(values.values, check_bounds=False)
    studied = studied_task(found, "its EMLA set and TCP force")
    count = len(found.planned["time"])
    tcp_force = _samples(studied.force, count)
    return MachinePlan(
        **found.planned,
        machine=machine,
        emlas=studied.study.emlas,
        tcp_force=tcp_force,
        payload_force=tcp_force - _samples(studied.soil, count),
        payload_kg=studied.task.payload.mass,
        tracked=getattr(studied.study.model, "extra", None),
        duty=studied.duty,
    )


def _samples(force: Array | None, count: int) -> Array:
    """A force of None, (3,) or (K, 3) as (K, 3) samples [N] (zero for None)."""
    if force is None:
        return np.zeros((count, 3))
    return np.asarray(np.broadcast_to(force, (count, 3)), dtype=float).copy()

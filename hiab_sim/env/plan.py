"""The optimiser's plan for one design (and one task of a duty mix), read from a result folder.

:func:`open_design` reads one design of any result folder (``result.json`` and ``trajectory.npz``)
into the fields every plan has (:class:`PlannedDesign`); a crane file's plan (:class:`DesignPlan`)
and a machine file's (:class:`hiab_sim.env.machine_plan.MachinePlan`) add their own.
``read_plan(result_dir, design)`` returns what the closed-loop validation needs: the crane, the EMLA
set and the payload of the study, the design's link lengths, its planned joint trajectory
(positions, rates, accelerations on the fine grid), the study's TCP reference and the optimiser's
predicted net electrical energy, through the one result-folder reader
(:func:`hiab_sim.results.read.open_run`).

A duty mix's result (``result.json`` ``tasks``) holds one plan per task: its own motion on its own
fine grid (``trajectory.npz`` ``task<k>_*``), its own payload and its own energies
(``tasks[k].<design>``); the top-level energies are the mix's weighted sums per hour, which no single
cycle can be compared with. Its plans are read per task (``task`` = k, :func:`mix_tasks`), and a
mix's plan is refused without one. The study file a result names gives each task's payload force F(t);
it is read only where it still holds the result's tasks, in the result's order (:func:`result_study`).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.emla.config import EmlaSet
from hiab_sim.emla.duty_energy import DutyOptions
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.results.read import DESIGNS, RunFolder, open_run, result_crane
from hiab_sim.results.schema import DesignSummary, Result, TaskResult
from hiab_sim.study.spec.study import Study
from hiab_sim.study.spec.study_file import load_study
from hiab_sim.study.spec.tasks import Task


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
        predicted_net_energy: The optimiser's net electrical energy of the design over one cycle [J] (a
            duty mix's task: the task's own, ``tasks[k].<design>``).
        task: The task's name in a duty mix's result, None for a single-task result.

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
    task: str | None = field(default=None, kw_only=True)

    @property
    def duration(self) -> float:
        """Cycle duration [s]."""
        return float(self.time[-1] - self.time[0])

    def force_at(self, force: Array, times: Array | None = None) -> Array:
        """A force of the fine grid, (K, 3) [N], at ``times`` [s] (N,): (N, 3), linear between the samples.

        ``times`` None: the fine grid's own (a copy of ``force``); before its first or after its last
        sample the end sample's force holds.
        """
        at = self.time if times is None else np.asarray(times, dtype=float)
        return np.stack([np.interp(at, self.time, force[:, i]) for i in range(3)], axis=1)


@dataclass(frozen=True)
class DesignPlan(PlannedDesign):
    """One design of a crane file's result (the fields of :class:`PlannedDesign` and the crane's).

    Attributes:
        crane: The crane description.
        lengths: The design's link lengths Xi [m].
        payload: Mass hanging at the TCP in the study (the task's) [kg].
        duty: The study's duty model of the cycle (hot windings, the rest's hold), or None: the
            paper's per-sample model (:func:`hiab_sim.study.nlp.task_setup.duty_options`).
        tcp_force: The payload's force on the TCP the plan's inverse dynamics took, (K, 3) [N] in {W}
            on the fine grid, where it is one per sample (a schedule m(t) or the payload's inertia:
            F(t) = m(t) (g - a_ref), :meth:`hiab_sim.study.spec.tasks.Task.id_force`); the closed loop
            applies it at the TCP. None: a constant weight, simulated as a point mass of ``payload``
            at the TCP.
        payload_force: The payload's share of ``tcp_force`` (without a soil's force), (K, 3) [N] in
            {W}: what an end-mass error scales; None with ``tcp_force`` None.

    """

    crane: Crane
    lengths: LinkLengths
    payload: float
    duty: DutyOptions | None = None
    tcp_force: Array | None = None
    payload_force: Array | None = None

    def id_tcp_force(self, times: Array | None = None) -> Array | None:
        """The TCP force of the plan's inverse dynamics [N] in {W} at ``times`` [s] (None: the fine grid's).

        (N, 3) where the plan has one per sample (linear between the fine grid's samples), else the
        payload's weight (0, -m g, 0), or None without a payload.
        """
        if self.tcp_force is not None:
            return self.force_at(self.tcp_force, times)
        if self.payload == 0.0:
            return None
        return np.array([0.0, -self.payload * self.crane.gravity, 0.0])


@dataclass(frozen=True)
class DesignRun:
    """One design of a result folder, read once for every kind of plan.

    Attributes:
        run: The folder as :func:`hiab_sim.results.read.open_run` read it.
        summary: The design's summary in ``result.json`` (a duty mix's task: the task's own).
        planned: The design's planned fields (:class:`PlannedDesign`'s, all but ``emlas``) from ``trajectory.npz``.
        task: The task of a duty mix's result (``result.json`` ``tasks[k]``), None for a single-task result.
        task_index: k of ``task`` (0 for a single-task result).

    """

    run: RunFolder[Result]
    summary: DesignSummary
    planned: dict[str, Any]
    task: TaskResult | None = None
    task_index: int = 0


def mix_tasks(result_dir: str | Path) -> tuple[TaskResult, ...]:
    """The tasks of a duty mix's result (``result.json`` ``tasks``), in their order; empty for a single-task result."""
    return tuple(open_run(result_dir, Result).result.tasks or ())


def open_design(result_dir: str | Path, design: str, task: int | None = None) -> DesignRun:
    """Read ``result.json`` and ``trajectory.npz`` of an ``hiab-sim optimize`` folder for one design (and task).

    ``task`` is the index k of a duty mix's task (module docstring), None for a single-task result.

    Raises:
        InvalidInputError: unknown design; a task index out of range, none for a duty mix, or one for a
            single-task result.
        ConfigError: the folder holds no result, or its files are malformed (one line naming them).

    """
    if design not in DESIGNS:
        raise InvalidInputError("design", design, f"must be one of {', '.join(DESIGNS)}")
    run = open_run(result_dir, Result)
    tasks = run.result.tasks or ()
    if not tasks and task is not None:
        raise InvalidInputError("task", task, "must be None for a single-task result (it holds one plan per design)")
    index = _task_index(task, tasks) if tasks else None
    trajectory = run.trajectory
    of_task = None if index is None else tasks[index]
    holder = run.result if of_task is None else of_task
    summary = holder.optimal if design == "optimal" else holder.initial
    prefix = "" if of_task is None else f"task{index}_"
    planned = {
        "design": design,
        "time": trajectory.time(prefix),
        "position": trajectory.design(design, "position", prefix),
        "velocity": trajectory.design(design, "velocity", prefix),
        "acceleration": trajectory.design(design, "acceleration", prefix),
        "reference_tcp": trajectory.get("reference_tcp", prefix),
        "predicted_electrical_power": trajectory.design(design, "electrical_power", prefix),
        "predicted_net_energy": float(summary.net_electrical_energy_J),
        "task": None if of_task is None else of_task.name,
    }
    return DesignRun(run, summary, planned, of_task, index or 0)


def _task_index(task: object, tasks: tuple[TaskResult, ...]) -> int:
    """``task`` as an index k of a duty mix's ``tasks`` (any integer type but bool, 0 <= k < n)."""
    if isinstance(task, numbers.Integral) and not isinstance(task, bool) and 0 <= int(task) < len(tasks):
        return int(task)
    names = ", ".join(f"{k}: {t.name}" for k, t in enumerate(tasks))
    raise InvalidInputError("task", task, f"must be a task index of the duty mix's result ({names})")


def read_plan(result_dir: str | Path, design: str, task: int | None = None) -> DesignPlan:
    """The plan of one design (and task) of a crane file's result (:func:`open_design`, the study's crane and EMLA set).

    The payload is the task's: its mass, and its force F(t) on the TCP where the plan's inverse dynamics
    took one per sample (:attr:`DesignPlan.tcp_force`; the study file is needed for it).

    Raises:
        InvalidInputError: unknown design, or a task index out of range (:func:`open_design`).
        ConfigError: the folder holds no result, or its files are malformed (one line naming them); a
            study file is gone (the plan's EMLA set, duty and payload forces are its); the study file
            no longer holds the result's tasks (:func:`result_study`).

    """
    found = open_design(result_dir, design, task)
    result = found.run.result
    studied = studied_task(found, "its EMLA set, duty and payload forces")
    tcp_force, payload_force = None, None
    if studied.force is not None and np.ndim(studied.force) == 2:  # one per sample: applied as a force
        tcp_force = np.asarray(studied.force, dtype=float)
        payload_force = tcp_force if studied.soil is None else tcp_force - studied.soil
    return DesignPlan(
        **found.planned,
        crane=result_crane(found.run.folder, result.crane),
        emlas=studied.study.emlas,
        lengths=crane_lengths(found.summary.lengths, "result"),
        payload=float(result.settings.payload_kg if found.task is None else found.task.payload_kg),
        duty=studied.duty,
        tcp_force=tcp_force,
        payload_force=payload_force,
    )


@dataclass(frozen=True)
class StudiedTask:
    """What a plan takes from the study file of its result for its task (:func:`studied_task`).

    Attributes:
        study: The study file, checked against the result (:func:`result_study`).
        task: The plan's task in it.
        duty: The study's duty model of the task's cycle, or None (the paper's per-sample model).
        force: The TCP force the optimiser's inverse dynamics took on the fine grid [N] in {W}
            (:meth:`~hiab_sim.study.spec.tasks.Task.id_force`: None, (3,) or (K, 3)).
        soil: The soil's share of it, (K, 3) [N], or None without soil.

    """

    study: Study
    task: Task
    duty: DutyOptions | None
    force: Array | None
    soil: Array | None


def studied_task(found: DesignRun, needed_for: str) -> StudiedTask:
    """The study, task, duty model and TCP forces of a plan's task on its fine grid (crane and machine alike)."""
    from hiab_sim.study.nlp.task_setup import duty_options

    spec, of_task = result_study(found, needed_for)
    time = found.planned["time"]
    kinematics, gravity = spec.model.kinematics, spec.model.gravity
    return StudiedTask(
        spec,
        of_task,
        duty_options(spec, spec.emlas, float(time[-1] - time[0])),
        of_task.id_force(kinematics, gravity, time),
        of_task.soil_force(kinematics, gravity, time),
    )


def result_study(found: DesignRun, needed_for: str) -> tuple[Study, Task]:
    """The study file the result names and its task of ``found``, checked against the result.

    The file may have changed since the run: it must hold as many tasks as the result (one for a
    single-task result) and, for a duty mix, the result's task k as its task k (by name), else a
    task's force F(t) would be another task's. ``needed_for`` says what the file is needed for (a
    closed loop on another EMLA set or duty than the plan's would compare unlike with unlike).

    Raises:
        ConfigError: the file is gone or malformed (naming ``needed_for``), or no longer holds the result's
            tasks in the result's order (one line naming the file and the task).

    """
    result, folder = found.run.result, found.run.folder
    try:
        spec = load_study(result.study)
    except ConfigError as error:
        raise ConfigError(f"{folder}: the study file {result.study} is needed for {needed_for} ({error})") from error
    planned = tuple(t.name for t in result.tasks or ())
    names, k = tuple(t.name for t in spec.tasks), found.task_index
    where = f"{folder}: the study file {result.study} holds"
    fix = "restore the study file the result was optimised with, or optimize again"
    if len(names) != max(len(planned), 1):
        held = f"the tasks ({', '.join(planned)})" if planned else "one task"
        raise ConfigError(f"{where} the tasks ({', '.join(names)}) where the result holds {held}; {fix}")
    if planned and names[k] != planned[k]:
        raise ConfigError(f"{where} {names[k]!r} as task {k} where the result's task {k} is {planned[k]!r}; {fix}")
    return spec, spec.tasks[k]

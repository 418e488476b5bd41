"""A study's tasks: each a name, a weight, a reference and a payload; ``tasks:`` or today's single reference.

Schema (a study file's top level; every other key is the study's, shared by all tasks)::

    tasks:
      - name: pick_and_place          # unique
        weight: 20                    # > 0: the task's share of the crane's work (e.g. cycles per hour)
        reference: {kind: pick_and_place, ...}   # spiral | pick_and_place | csv (hiab_sim.study.references.kinds)
        payload: {mass: 200, pick: 0.75, release: 14.25}   # or a number [kg]; default 0
        control_points: 30            # optional: the task's spline; default in proportion to its duration

Without ``tasks:``, today's ``reference:`` (a spiral unless it names another ``kind``) and
``payload:`` make one task named after the study, with weight 1, so every existing study file
keeps its meaning. A payload's pick and release must lie within the task's duration.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.references.csv_file import ColumnNames
from hiab_sim.study.references.kinds import TaskReference, reference_from_mapping
from hiab_sim.study.spec.payload import Payload
from hiab_sim.study.spec.soil_contact import SoilContact
from hiab_sim.yaml_fields import mapping, number

if TYPE_CHECKING:
    from hiab_sim.crane.description import Crane
    from hiab_sim.study.machines.protocol import Kinematics, StudyMachine


@dataclass(frozen=True)
class Task:
    """One duty cycle of the crane (module docstring).

    Attributes:
        name: Unique name, used in reports and messages.
        weight: Share of the crane's work (> 0); the mix's objective is sum weight_i f_i.
        reference: What the TCP and the telescope must do.
        payload: The mass at the TCP and when it is held.
        control_points: Spline control points of the task's trajectory, or None (by duration).
        soil: The soil the tool cuts (its force on the TCP along the reference), or None.

    """

    name: str
    weight: float
    reference: TaskReference
    payload: Payload
    control_points: int | None = None
    soil: SoilContact | None = None

    def __post_init__(self) -> None:
        if not self.name:
            raise InvalidInputError("task.name", self.name, "must be a non-empty string")
        if not (math.isfinite(self.weight) and self.weight > 0.0):
            raise InvalidInputError("weight", self.weight, "must be > 0 and finite")
        duration = self.reference.duration
        for key in ("pick", "release"):
            value = getattr(self.payload, key)
            if value is not None and value > duration:
                raise InvalidInputError(
                    f"payload.{key}", value, f"must lie within the task's duration [0, {duration:.6g}]", "s"
                )

    def spline_points(self, points: int, per_duration: float, degree: int) -> int:
        """Control points: the task's own, or ``points`` per ``per_duration`` [s] scaled to its duration."""
        if self.control_points is not None:
            return self.control_points
        return max(degree + 2, round(points * self.reference.duration / per_duration))

    def times(self, step: float) -> Array:
        """Collocation times on [0, duration] [s] with a step <= ``step`` [s]."""
        duration = self.reference.duration
        return np.linspace(0.0, duration, max(2, math.ceil(duration / step - 1e-9)) + 1)

    def tcp_force(self, kin: Kinematics, gravity: float, times: Array) -> Array | None:
        """Payload force on the TCP at ``times``, (K, 3) in {W} [N] (reference's acceleration); None without mass."""
        if self.payload.mass == 0.0:
            return None
        acceleration = self.reference.sample(kin, times).acceleration[:, :2]
        return self.payload.tcp_force(times, acceleration, gravity)

    def soil_force(self, kin: Kinematics, gravity: float, times: Array) -> Array | None:
        """The soil's force on the TCP at ``times``, (K, 3) in {W} [N] (on the reference); None without soil."""
        if self.soil is None:
            return None
        ref = self.reference.sample(kin, times)
        return self.soil.force(tuple(getattr(kin, "names", ())), ref.position, ref.velocity, gravity)

    def id_force(self, kin: Kinematics, gravity: float, times: Array) -> Array | None:
        """The payload's force on the TCP as the inverse dynamics takes it [N] in {W}: None, (3,) or (K, 3).

        A constant weight without inertia (a single-reference study's plain ``payload: <kg>``) is
        the constant vector (0, -m g, 0), as before tasks; a schedule or a payload with inertia is
        the per-sample F(t) of :meth:`tcp_force` (at the reference's acceleration, so it does not
        depend on the NLP's variables).
        """
        payload = self.payload
        soil = self.soil_force(kin, gravity, times)
        if payload.mass == 0.0:
            return soil
        if payload.pick is None and payload.release is None and not payload.inertia and soil is None:
            return np.array([0.0, -payload.mass * gravity, 0.0])
        carried = self.tcp_force(kin, gravity, times)
        assert carried is not None
        if carried.ndim == 1:
            carried = np.broadcast_to(carried, (len(np.asarray(times)), 3))
        return carried if soil is None else carried + soil


def tasks_from_mapping(
    top: Mapping[str, Any],
    folder: Path,
    grid_duration: float,
    study_name: str,
    names: ColumnNames,
) -> tuple[Task, ...]:
    """The study's tasks from its top-level mapping (``tasks:`` or today's ``reference:`` + ``payload:``).

    In the single-reference form a plain ``payload: <kg>`` keeps today's meaning: its weight only (no
    inertia); a payload mapping or a task's payload says whether it has inertia.

    Args:
        top: The study file's parsed top level.
        folder: The study file's folder (CSV paths resolve there).
        grid_duration: ``grid.duration`` [s], a spiral's default duration.
        study_name: Name of the single task of the one-reference form.
        names: The machine's tracked coordinates beyond the TCP's x, y, and its joints (CSV columns).

    """
    if "tasks" not in top and "reference" not in top:
        raise ConfigError("study: give 'tasks:' (a list of tasks) or 'reference:' (one task)")
    if "tasks" not in top:
        reference = reference_from_mapping(top["reference"], "reference", folder, grid_duration, names)
        value = top.get("payload", 0.0)
        payload = Payload.from_value(value)
        if isinstance(value, int | float):
            payload = replace(payload, inertia=False)
        return (Task(study_name, 1.0, reference, payload),)
    if "reference" in top or "payload" in top:
        raise ConfigError("study: give either 'tasks:' or 'reference:' (with 'payload:'), not both")
    entries = top["tasks"]
    if not isinstance(entries, list) or not entries:
        raise ConfigError(f"tasks: expected a non-empty list of tasks, got {entries!r}")
    tasks = []
    for i, entry in enumerate(entries):
        where = f"tasks[{i}]"
        keys = {"name", "weight", "reference", "payload", "control_points", "soil"}
        d = mapping(entry, where, keys, {"name", "weight", "reference"})
        points = d.get("control_points")
        if points is not None and (isinstance(points, bool) or not isinstance(points, int) or points < 7):
            raise InvalidInputError(f"{where}.control_points", points, "must be an integer >= 7")
        try:
            task = Task(
                name=str(d["name"]),
                weight=number(d["weight"], f"{where}.weight"),
                reference=reference_from_mapping(d["reference"], f"{where}.reference", folder, grid_duration, names),
                payload=Payload.from_value(d.get("payload", 0.0), f"{where}.payload"),
                control_points=points,
                soil=None if d.get("soil") is None else SoilContact.from_mapping(d["soil"], f"{where}.soil", folder),
            )
        except InvalidInputError as error:
            raise InvalidInputError(_prefixed(where, error.field), error.value, error.allowed, error.unit) from None
        tasks.append(task)
    task_names = [t.name for t in tasks]
    duplicate = next((n for n in task_names if task_names.count(n) > 1), None)
    if duplicate is not None:
        raise ConfigError(f"tasks: the name {duplicate!r} is used twice; task names must be unique")
    return tuple(tasks)


def column_names(model: StudyMachine) -> ColumnNames:
    """A trajectory file's column names for ``model``: its tracked coordinates beyond the TCP's x, y, and its joints."""
    return tuple(model.tracked_names[2:]), tuple(model.joint_names)


def check_tasks(tasks: tuple[Task, ...], kin: Kinematics, model: StudyMachine | Crane) -> None:
    """Every task's reference within the machine's reach and joint ranges; the error names the task."""
    for i, task in enumerate(tasks):
        try:
            task.reference.check_reach(kin, model)
        except InvalidInputError as error:
            field = f"tasks[{i}] ({task.name}) {error.field}"
            raise InvalidInputError(field, error.value, error.allowed, error.unit) from None


def _prefixed(where: str, field: str) -> str:
    return field if field.startswith(where) else f"{where}.{field}"

"""The study: everything one optimisation needs, as one frozen dataclass (a crane file's or a machine file's)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import cast

from hiab_sim.crane.description import Crane
from hiab_sim.crane.mounting import MountingSpace
from hiab_sim.emla.config import EmlaSet
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.mounting import MachineMountingSpace
from hiab_sim.resources import Source
from hiab_sim.structure.settings import StructureSettings
from hiab_sim.study.machines.crane_model import CraneModel
from hiab_sim.study.machines.machine_model import MachineModel
from hiab_sim.study.machines.protocol import Design, StudyMachine
from hiab_sim.study.references.kinds import TaskReference
from hiab_sim.study.spec.build import BuildSettings
from hiab_sim.study.spec.energy import EnergySettings
from hiab_sim.study.spec.settings import Bounds, GridSettings, SolverSettings, SplineSettings, Tracking
from hiab_sim.study.spec.tasks import Task


@dataclass(frozen=True)
class Study:
    """Everything one optimisation needs (see module docstring).

    ``crane_source`` and ``emla_source`` are what the study file wrote (a preset name or a path
    relative to it), kept for reports; ``crane_file`` is where the crane was read from, for
    copying a crane file next to a result. A study of a machine file (``machine:``) has no crane
    description (``crane_description`` None, ``machine`` its :class:`~hiab_sim.machine.description.Machine`);
    :attr:`model` is the machine as the NLP sees it either way.
    """

    name: str
    path: str
    crane_source: str
    crane_description: Crane | None = field(repr=False)
    emla_source: str
    emlas: EmlaSet = field(repr=False)
    initial_lengths: Design
    spline: SplineSettings
    grid: GridSettings
    tasks: tuple[Task, ...]
    tracking: Tracking
    bounds: Bounds
    solver: SolverSettings
    build: BuildSettings = field(default_factory=BuildSettings)  # manufacturing tolerance, stroke margin
    mounting: MountingSpace | MachineMountingSpace | None = None  # optional mounting space of the moved pivots
    crane_file: Source | None = field(default=None, repr=False, compare=False)
    #: The built crane's lengths when they lie outside the bounds and the loader moved the start into them.
    start_moved_from: Design | None = field(default=None, repr=False, compare=False)
    energy: EnergySettings = field(default_factory=EnergySettings)  # objective, duty, transmission
    structure: StructureSettings = field(default_factory=StructureSettings)  # buckling, pin and frequency rows
    machine: Machine | None = field(default=None, repr=False)  # a machine file's description (``machine:``)
    tracked: tuple[str, ...] = ()  # a machine's tracked coordinates beyond the TCP's x, y

    def __post_init__(self) -> None:
        if not self.tasks:
            raise InvalidInputError("tasks", 0, "a study needs at least one task")
        if (self.crane_description is None) == (self.machine is None):
            raise InvalidInputError("machine", self.crane_source, "a study needs exactly one of crane: or machine:")
        if self.energy.duty is not None:
            for task in self.tasks:  # the duty must fit each task's cycle (named error otherwise)
                self.energy.duty.duty(task.reference.duration)
        names = self.model.design_names
        if len(self.bounds.xi_low) != len(names):
            raise InvalidInputError("bounds", len(self.bounds.xi_low), f"need one per decision variable: {names}")
        for k, (name, start) in enumerate(zip(names, self.initial_lengths.as_array(), strict=True)):
            low, up = self.bounds.xi_low[k], self.bounds.xi_up[k]
            if not low <= start <= up:
                raise InvalidInputError(
                    f"initial_lengths.{name}", float(start), f"must lie in the bounds [{low:.6g}, {up:.6g}]", "m"
                )
        catalogue = self.energy.transmission
        unknown = [] if catalogue is None else [n for n, _ in catalogue.options if n not in self.emlas.names]
        if unknown:
            raise InvalidInputError(
                "transmission", ", ".join(unknown), f"keys must be the study's actuators: {', '.join(self.emlas.names)}"
            )
        if len(self.bounds.joint_velocity) != len(self.model.joint_names):
            raise InvalidInputError(
                "bounds.joint_velocity",
                len(self.bounds.joint_velocity),
                f"need one limit per joint: {', '.join(self.model.joint_names)}",
            )

    @property
    def crane(self) -> Crane:
        """The crane description (a crane-file study only; the parts of hiab-sim not yet on machine files need it)."""
        if self.crane_description is None:
            raise InvalidInputError(
                "machine", self.crane_source, "this part of hiab-sim needs a crane file (crane:), not a machine file"
            )
        return self.crane_description

    @property
    def model(self) -> StudyMachine:
        """The machine as the NLP sees it (:mod:`hiab_sim.study.machines`), built once."""
        cached = self.__dict__.get("_model")
        if cached is None:
            if self.crane_description is not None:
                cached = CraneModel(self.crane_description)
            else:
                assert self.machine is not None
                cached = MachineModel(self.machine, self.tracked)
            object.__setattr__(self, "_model", cached)
        return cast("StudyMachine", cached)

    @property
    def reference(self) -> TaskReference:
        """The reference of a single-task study (the first task's otherwise)."""
        return self.tasks[0].reference

    @property
    def payload(self) -> float:
        """Payload mass of a single-task study [kg] (the largest over the tasks otherwise)."""
        return max(task.payload.mass for task in self.tasks)

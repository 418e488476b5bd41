"""Study YAML -> frozen dataclasses: crane, EMLAs, spline, grid, tasks (references, payloads), bounds, solver.

A study file names everything the optimiser of seed eqs. ``costf2`` / ``const_a``..``const_m``
needs; every unknown or missing key raises :class:`~hiab_sim.errors.ConfigError` and every
out-of-range value :class:`~hiab_sim.errors.InvalidInputError` naming the field. Values are read
by :mod:`hiab_sim.yaml_fields`; each dataclass checks its own ranges in ``__post_init__`` and
holds the only copy of its defaults (a key a file omits takes the dataclass default). The crane
and the EMLA set are a preset name or a path, resolved by :func:`hiab_sim.resources.locate`:
relative paths next to the study file (inside the installed package for a shipped study).

The study's work is a tuple of tasks (:mod:`hiab_sim.study.spec.tasks`): a ``tasks:`` list, or today's
single ``reference:`` (+ ``payload:``), which is one task named after the study with weight 1. In
that single-reference form a plain ``payload: <kg>`` keeps today's meaning, the payload's weight
only (``Payload(mass, inertia=False)``), so the results of existing study files do not change;
within ``tasks:`` a plain number is a constant mass with its inertia (see :mod:`.payload`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, cast

import numpy as np

from hiab_sim.checks import check_choice, check_range
from hiab_sim.crane.description import CHAIN_NAMES, ChainLengths, Crane, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.crane.mounting import MountingSpace
from hiab_sim.emla.config import EmlaSet, load_emla_set
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.loader import PRESETS as MACHINE_PRESETS
from hiab_sim.machine.loader import load_machine, locate_machine
from hiab_sim.resources import DEFAULT_STUDY, Source, locate
from hiab_sim.structure.settings import StructureSettings
from hiab_sim.study.machines.crane_model import CraneModel
from hiab_sim.study.machines.machine_model import MachineModel
from hiab_sim.study.machines.protocol import Design, StudyMachine
from hiab_sim.study.references.kinds import TaskReference
from hiab_sim.study.spec.build import BuildSettings
from hiab_sim.study.spec.energy import ENERGY_KEYS, EnergySettings, energy_settings
from hiab_sim.study.spec.tasks import Task, tasks_from_mapping
from hiab_sim.yaml_fields import mapping, number, positive, read_yaml, section, vector

ID_PATHS = ("mujoco", "analytic")


@dataclass(frozen=True)
class SplineSettings:
    """Joint-trajectory B-splines (eqs. ``matrix_basis``..``matrix_basis_dd``).

    Attributes:
        control_points: N, control points per joint (seed: 22).
        degree: Polynomial degree k >= 3 (5: quintic, continuous jerk, so forces are C^2 in time).

    """

    control_points: int = 22
    degree: int = 5

    def __post_init__(self) -> None:
        check_range("spline.degree", self.degree, 3, 7, integral=True)
        check_range("spline.control_points", self.control_points, max(6, self.degree + 2), integral=True)


@dataclass(frozen=True)
class GridSettings:
    """Collocation grid T = {0, dt, ..., duration} (seed: M = 25 intervals over 6.25 s).

    Attributes:
        duration: Trajectory duration [s].
        intervals: M, number of collocation intervals (M + 1 points).
        fine_factor: The independent re-check grid has ``fine_factor * M`` intervals.

    """

    duration: float = 6.25
    intervals: int = 25
    fine_factor: int = 10

    def __post_init__(self) -> None:
        check_range("grid.duration", self.duration, 0.0, unit="s", low_open=True)
        check_range("grid.intervals", self.intervals, 2, integral=True)
        check_range("grid.fine_factor", self.fine_factor, 1, integral=True)

    @property
    def dt(self) -> float:
        """Collocation step Delta_t [s] of eq. ``costf2``."""
        return self.duration / self.intervals

    def times(self) -> np.ndarray:
        """Collocation times, shape (M + 1,) [s]."""
        return np.linspace(0.0, self.duration, self.intervals + 1)

    def fine_times(self) -> np.ndarray:
        """Re-check times, ``fine_factor`` times denser, shape (fine_factor M + 1,) [s]."""
        return np.linspace(0.0, self.duration, self.fine_factor * self.intervals + 1)


@dataclass(frozen=True)
class Tracking:
    """Tolerance bands of the TCP tracking constraints (const_b, const_c, const_d) at collocation points.

    Attributes:
        position: |x_r - G_tcp(theta)| per coordinate [m] (xt2 in [m] too).
        velocity: [m/s].
        acceleration: [m/s^2].
        collocation_fraction: The optimiser holds the bands times this fraction at the
            collocation points, so the full bands hold between them (checked on the fine grid).

    """

    position: float = 1e-3
    velocity: float = 5e-3
    acceleration: float = 5e-2
    collocation_fraction: float = 0.5

    def __post_init__(self) -> None:
        check_range("tracking.position", self.position, 0.0, unit="m", low_open=True)
        check_range("tracking.velocity", self.velocity, 0.0, unit="m/s", low_open=True)
        check_range("tracking.acceleration", self.acceleration, 0.0, unit="m/s^2", low_open=True)
        check_range("tracking.collocation_fraction", self.collocation_fraction, 0.0, 1.0, low_open=True)


@dataclass(frozen=True)
class Bounds:
    """Box and path bounds of the NLP.

    Attributes:
        xi_low: Lower bounds of Xi, (lift L, Lc0, Lc, tilt L, Lc0, Lc) [m] (const_g).
        xi_up: Upper bounds of Xi [m] (const_g).
        joint_velocity: |dtheta1|, |dtheta2| [rad/s], |dxt2| [m/s] limits (const_i).
        triangle_margin: Smallest interior angle of each chain's triangle at the boom hinge
            and its supplement, [rad] (const_k with a margin from the flat triangle).
        working_range: ``crane``: the design must serve the crane's full joint range (const_j at
            its ends), i.e. keep the crane's workspace; ``reference``: only the reference's joint
            range widened by ``working_margin`` [rad] at both ends.
        envelope_margin: The optimiser keeps the EMLA envelope margins >= this at the
            collocation points, so they stay >= 0 between them (checked on the fine grid).

    """

    xi_low: tuple[float, ...]
    xi_up: tuple[float, ...]
    joint_velocity: tuple[float, ...] = (0.6, 0.6, 0.5)
    triangle_margin: float = math.radians(10.0)
    working_margin: float = math.radians(3.0)
    envelope_margin: float = 0.02
    working_range: str = "crane"
    #: where each bound comes from, for messages (default: the crane's ``bounds.<chain>.low[i] (key)``)
    xi_fields: tuple[str, ...] = field(default=(), compare=False, repr=False)

    def __post_init__(self) -> None:
        for i, (low, up) in enumerate(zip(self.xi_low, self.xi_up, strict=True)):
            where = (
                self.xi_fields[i]
                if self.xi_fields
                else f"bounds.{CHAIN_NAMES[i // 3]}.low[{i % 3}] ({('L', 'Lc0', 'Lc')[i % 3]})"
            )
            if not low < up or (not self.xi_fields and not 0.0 < low):
                raise InvalidInputError(
                    where, low, f"must satisfy {'' if self.xi_fields else '0 < '}low < up = {up:.6g}", "m"
                )
        if min(self.joint_velocity) <= 0.0:
            raise InvalidInputError("bounds.joint_velocity", min(self.joint_velocity), "every limit must be > 0")
        margin = math.degrees(self.triangle_margin)
        check_range("bounds.triangle_margin_deg", margin, 0.0, 60.0, "deg", high_open=True)
        check_range("bounds.working_margin_deg", math.degrees(self.working_margin), 0.0, 30.0, "deg")
        check_range("bounds.envelope_margin", self.envelope_margin, 0.0, 0.5, high_open=True)
        check_choice("bounds.working_range", self.working_range, ("crane", "machine", "reference"))


@dataclass(frozen=True)
class SolverSettings:
    """SQP settings (scipy SLSQP).

    Attributes:
        maxiter: Largest number of SQP iterations.
        ftol: SLSQP's ``ftol`` on the scaled cost.
        id_path: Inverse-dynamics path of the optimisation (the re-check uses the other one).
        fd_step: Relative central-difference step of the inverse-dynamics derivatives.
        xi_derivatives: ``analytic``: d(f_x, v_x)/dXi by central differences on the analytic ID
            path (no model rebuild; it agrees with the MuJoCo path to ~1e-14 relative, re-checked
            in every result); ``rebuild``: on the optimisation's own path with model rebuilds.
        method: ``slsqp`` (scipy, dense; the single-task default) or ``ipopt`` (CasADi's IPOPT
            with sparse Jacobians, for duty mixes: :mod:`hiab_sim.study.solvers.ipopt`).

    """

    maxiter: int = 100
    ftol: float = 1e-9
    id_path: str = "mujoco"
    fd_step: float = 1e-6
    xi_derivatives: str = "analytic"
    method: str = "slsqp"

    def __post_init__(self) -> None:
        check_range("solver.maxiter", self.maxiter, 1, integral=True)
        check_range("solver.ftol", self.ftol, 0.0, low_open=True)
        check_choice("solver.id_path", self.id_path, ID_PATHS)
        check_range("solver.fd_step", self.fd_step, 0.0, low_open=True)
        check_choice("solver.xi_derivatives", self.xi_derivatives, ("analytic", "rebuild"))
        check_choice("solver.method", self.method, ("slsqp", "ipopt"))


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
    mounting: MountingSpace | None = None  # optional mounting polygons of the base pivots
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


_TOP = {
    "name",
    "crane",
    "machine",
    "tracked",
    "emla",
    "initial_lengths",
    "spline",
    "grid",
    "reference",
    "tracking",
    "bounds",
    "solver",
    "payload",
    *ENERGY_KEYS,
    "tasks",
    "build",
    "mounting",
    "structure",
}
_REQUIRED_TOP = {"bounds"}


def load_study(path: str | Path | Source | None = None) -> Study:
    """Load and validate a study: a shipped name (``xs031_spiral``, the default) or a YAML path.

    Raises:
        ConfigError: Missing file, malformed YAML, unknown or missing keys, wrong types.
        InvalidInputError: A value out of range, named by its field.

    """
    if isinstance(path, Source):
        found = path
    else:
        found = locate(DEFAULT_STUDY if path is None else path, "study")
    return study_from_dict(read_yaml(found), found)


def study_from_dict(data: Any, file: str | Path | Source = "<study>") -> Study:
    """Build a :class:`Study` from a parsed YAML mapping (relative paths resolve next to ``file``)."""
    if not isinstance(file, Source):
        file = Source(str(file), Path(file), shipped=False)
    top = mapping(data, "study", _TOP, _REQUIRED_TOP)
    if "machine" in top:
        return machine_study_from_dict(dict(top), file)
    if "crane" not in top:
        raise ConfigError("study: missing key 'crane' (a crane file) or 'machine' (a machine file)")
    if "tracked" in top:
        raise ConfigError("study: 'tracked' belongs to a machine file's study (machine:); a crane tracks x, y, xt2")
    crane_source = str(top["crane"])
    crane_file = locate(crane_source, "crane", relative_to=file)
    crane = load_crane(crane_file)
    emla_source = "default" if top.get("emla") is None else str(top["emla"])
    emlas = load_emla_set(locate(emla_source, "emla", relative_to=file)).renamed(CraneModel(crane).actuator_names)
    bounds = _bounds(top["bounds"])
    grid = GridSettings(**section(GridSettings, top.get("grid"), "grid"))
    name = str(top.get("name", Path(str(file.file)).stem))
    if "tasks" not in top and "reference" not in top:
        raise ConfigError("study: give 'tasks:' (a list of tasks) or 'reference:' (one task)")
    tasks = tasks_from_mapping(top, Path(str(file.file)).parent, grid.duration, name)
    if "tasks" not in top and isinstance(top.get("payload", 0.0), int | float):
        # single-reference form: a plain number is today's payload, its weight only (module docstring)
        tasks = (replace(tasks[0], payload=replace(tasks[0].payload, inertia=False)),)
    initial = _lengths(top.get("initial_lengths"), crane, bounds)
    moved = "initial_lengths" not in top and initial != crane.default_lengths
    return Study(
        name=name,
        path=str(file.file),
        crane_source=crane_source,
        crane_description=crane,
        emla_source=emla_source,
        emlas=emlas,
        initial_lengths=initial,
        spline=SplineSettings(**section(SplineSettings, top.get("spline"), "spline")),
        grid=grid,
        tasks=tasks,
        tracking=Tracking(**section(Tracking, top.get("tracking"), "tracking")),
        bounds=bounds,
        solver=SolverSettings(**section(SolverSettings, top.get("solver"), "solver")),
        build=BuildSettings.from_mapping(top.get("build")),
        mounting=None if top.get("mounting") is None else MountingSpace.from_mapping(top["mounting"]),
        crane_file=crane_file,
        start_moved_from=crane.default_lengths if moved else None,
        energy=energy_settings(top),
        structure=StructureSettings.from_mapping(top.get("structure"), crane),
    )


def _lengths(data: Any, crane: Crane, bounds: Bounds) -> LinkLengths:
    if data is None:  # the crane's own lengths, clipped into the bounds (the feasibility phase moves on from there)
        return _clipped_lengths(crane, bounds)
    top = mapping(data, "initial_lengths", set(CHAIN_NAMES), set(CHAIN_NAMES))
    chains = []
    for name in CHAIN_NAMES:
        d = mapping(top[name], f"initial_lengths.{name}", {"L", "Lc0", "Lc"}, {"L", "Lc0", "Lc"})
        values = [positive(d[k], f"initial_lengths.{name}.{k}", "m") for k in ("L", "Lc0", "Lc")]
        chains.append(ChainLengths(*values))
    return LinkLengths(chains[0], chains[1])


def _clipped_lengths(crane: Crane, bounds: Bounds) -> LinkLengths:
    """The crane's lengths if inside the bounds; else L clipped and x0 = Lc0 + Lc centring the joint range's stroke.

    A clipped L moves the strokes at the ends of the joint range (eq. qus_a); x0 is chosen so the
    stroke used, s(theta_up) - s(theta_low), sits in the middle of [0, stroke], and Lc takes what
    Lc0 (clipped) leaves, within its bounds. The feasibility phase starts from this point.
    """
    xi = crane.default_lengths.as_array()
    low, up = np.asarray(bounds.xi_low), np.asarray(bounds.xi_up)
    if np.all((low <= xi) & (xi <= up)):
        return crane.default_lengths
    out = np.clip(xi, low, up)
    for j, chain in enumerate(crane.chains):
        if out[3 * j] == xi[3 * j]:
            continue
        q = chain.joint_offset - math.pi - np.asarray(chain.joint_range)  # hinge angle (eq. thetas)
        s = np.sqrt(out[3 * j] ** 2 + chain.L1**2 - 2.0 * out[3 * j] * chain.L1 * np.cos(q))
        x0 = 0.5 * (float(s.min() + s.max()) - chain.stroke)
        out[3 * j + 2] = float(np.clip(x0 - out[3 * j + 1], low[3 * j + 2], up[3 * j + 2]))
    return LinkLengths.from_array(out)


def _bounds(data: Any, chains: bool = True, joints: int = 3) -> Bounds:
    """Bounds from YAML: per chain ``low``/``up`` triples, ``joint_velocity`` one per joint, angles in degrees.

    A crane file's study gives the chains' bounds; a machine file declares its own (``chains`` False)
    and its study must give ``joint_velocity`` (``joints`` limits).
    """
    keys = {
        "joint_velocity",
        "triangle_margin_deg",
        "working_range",
        "working_margin_deg",
        "envelope_margin",
    }
    chain_keys = set(CHAIN_NAMES) if chains else set()
    d = mapping(data, "bounds", keys | chain_keys, chain_keys if chains else {"joint_velocity"})
    low: list[float] = []
    up: list[float] = []
    for name in sorted(chain_keys, key=CHAIN_NAMES.index):
        chain = mapping(d[name], f"bounds.{name}", {"low", "up"}, {"low", "up"})
        low += vector(chain["low"], f"bounds.{name}.low", 3)
        up += vector(chain["up"], f"bounds.{name}.up", 3)
    values: dict[str, Any] = {"xi_low": tuple(low), "xi_up": tuple(up)}
    if "joint_velocity" in d:
        values["joint_velocity"] = vector(d["joint_velocity"], "bounds.joint_velocity", joints)
    for key in ("triangle_margin", "working_margin"):
        if f"{key}_deg" in d:
            values[key] = math.radians(number(d[f"{key}_deg"], f"bounds.{key}_deg"))
    if "envelope_margin" in d:
        values["envelope_margin"] = number(d["envelope_margin"], "bounds.envelope_margin")
    if "working_range" in d:
        values["working_range"] = str(d["working_range"])
    return Bounds(**values)


def machine_study_from_dict(top: dict[str, Any], file: Source) -> Study:
    """A study of a machine file (``machine:``): its decision variables, their bounds and its names are the file's.

    Keys as a crane study's, except: ``machine`` (a shipped machine or a path next to the study),
    ``tracked`` (the tracked coordinates beyond the TCP's x, y: joint names or ``tcp_angle``;
    default ``tcp_angle`` for each), ``initial_lengths`` (a mapping ``chain.variable: value``, default
    the file's values) and ``bounds`` without per-chain bounds (the file declares them). ``build``,
    ``mounting`` and ``structure`` need a crane file for now and are refused.
    """
    for key in ("crane", "mounting", "structure", "build"):
        if key in top:
            raise ConfigError(f"study: '{key}' is not available for a machine file (machine:) yet; remove it")
    source = str(top["machine"])
    path = Path(source)
    folder = Path(str(file.file)).parent
    if source not in MACHINE_PRESETS and not path.is_absolute() and (folder / path).is_file():
        path = folder / path
    machine_file = locate_machine(source if source in MACHINE_PRESETS else path)
    machine = load_machine(machine_file)
    n = len(machine.joint_names)
    tracked_value = top.get("tracked", ["tcp_angle"] * (n - 2))
    if not isinstance(tracked_value, list) or not all(isinstance(t, str) for t in tracked_value):
        raise ConfigError(f"study: tracked: expected a list of names, got {tracked_value!r}")
    tracked = tuple(tracked_value)
    model = MachineModel(machine, tracked)
    emla_source = str(top.get("emla", ""))
    if not emla_source:
        raise ConfigError("study: a machine file's study names its EMLA file (emla:)")
    emlas = load_emla_set(locate(emla_source, "emla", relative_to=file)).renamed(model.actuator_names)
    low, up = model.design_bounds()
    bounds = _bounds(top["bounds"], chains=False, joints=n)
    bounds = replace(
        bounds,
        xi_low=tuple(map(float, low)),
        xi_up=tuple(map(float, up)),
        xi_fields=tuple(
            f"{machine_file.label}: chains.{k.replace('.', '.variables.')}.bounds" for k in model.design_names
        ),
    )
    grid = GridSettings(**section(GridSettings, top.get("grid"), "grid"))
    name = str(top.get("name", Path(str(file.file)).stem))
    if "tasks" not in top and "reference" not in top:
        raise ConfigError("study: give 'tasks:' (a list of tasks) or 'reference:' (one task)")
    names = (tuple(model.tracked_names[2:]), model.joint_names)
    tasks = tasks_from_mapping(top, folder, grid.duration, name, names)
    if "tasks" not in top and isinstance(top.get("payload", 0.0), int | float):
        tasks = (replace(tasks[0], payload=replace(tasks[0].payload, inertia=False)),)
    for i, task in enumerate(tasks):
        if task.reference.kind != "csv":
            raise ConfigError(
                f"study: tasks[{i}] ({task.name}): a machine file's study takes 'kind: csv' references "
                f"(got '{task.reference.kind}'; the spiral and pick-and-place kinds prescribe a crane's telescope)"
            )
    initial = model.default_design
    if "initial_lengths" in top:
        given = mapping(top["initial_lengths"], "initial_lengths", set(model.design_names), set())
        values = initial.as_array()
        for key, value in given.items():
            values[model.design_names.index(key)] = number(value, f"initial_lengths.{key}")
        initial = model.design(values)
    return Study(
        name=name,
        path=str(file.file),
        crane_source=source,
        crane_description=None,
        emla_source=emla_source,
        emlas=emlas,
        initial_lengths=initial,
        spline=SplineSettings(**section(SplineSettings, top.get("spline"), "spline")),
        grid=grid,
        tasks=tasks,
        tracking=Tracking(**section(Tracking, top.get("tracking"), "tracking")),
        bounds=bounds,
        solver=SolverSettings(**section(SolverSettings, top.get("solver"), "solver")),
        crane_file=machine_file,
        energy=energy_settings(top),
        machine=machine,
        tracked=tracked,
    )

"""A study's settings sections: spline, grid, tracking bands, bounds and solver (frozen, validated when built).

Each dataclass holds the only copy of its defaults (a key a study file omits takes it) and checks its
own ranges in ``__post_init__``; :func:`bounds_from_mapping` reads the ``bounds:`` section.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.checks import check_choice, check_range
from hiab_sim.crane.description import CHAIN_NAMES
from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.errors import InvalidInputError
from hiab_sim.resources import Source, recorded_path
from hiab_sim.study.references.csv_file import ColumnNames
from hiab_sim.study.spec.build import BuildSettings
from hiab_sim.study.spec.energy import energy_settings
from hiab_sim.study.spec.tasks import tasks_from_mapping
from hiab_sim.yaml_fields import mapping, number, section, vector

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
        joint_derivatives: Path of d(f_x, v_x, a_x)/d(q, dq, ddq) (central differences):
            ``path``, the optimisation's own; ``analytic``, the analytic path's (vectorised over
            samples). Default (unset): ``analytic`` on a machine file, where the MuJoCo path projects
            the loops sample by sample and is ~30x slower at it, equal to it to ~1e-9 relative;
            ``path`` on a crane file, which every shipped crane study was solved with (on
            xs031_spiral_energy ``analytic`` moves the optimum by 1.1e-6 m and 3 iterations).
        method: ``slsqp`` (scipy, dense; the single-task default) or ``ipopt`` (CasADi's IPOPT
            with sparse Jacobians, for duty mixes: :mod:`hiab_sim.study.solvers.ipopt`).
        lbfgs_history: IPOPT only: how many (step, gradient change) pairs its limited-memory
            quasi-Newton Hessian keeps (IPOPT's ``limited_memory_max_history``; its default 6).
            More pairs cost a larger KKT system per iteration and can save many iterations on a
            flat optimum (the digging study: 282 iterations with 6, 111 with 50, the same point
            to 1e-5 m; ``benchmarks/bench_machine_study.py``).

    """

    maxiter: int = 100
    ftol: float = 1e-9
    id_path: str = "mujoco"
    fd_step: float = 1e-6
    xi_derivatives: str = "analytic"
    joint_derivatives: str | None = None
    method: str = "slsqp"
    lbfgs_history: int = 6

    def __post_init__(self) -> None:
        check_range("solver.maxiter", self.maxiter, 1, integral=True)
        check_range("solver.ftol", self.ftol, 0.0, low_open=True)
        check_choice("solver.id_path", self.id_path, ID_PATHS)
        check_range("solver.fd_step", self.fd_step, 0.0, low_open=True)
        check_choice("solver.xi_derivatives", self.xi_derivatives, ("analytic", "rebuild"))
        if self.joint_derivatives is not None:
            check_choice("solver.joint_derivatives", self.joint_derivatives, ("path", "analytic"))
        check_choice("solver.method", self.method, ("slsqp", "ipopt"))
        check_range("solver.lbfgs_history", self.lbfgs_history, 1, 500, integral=True)


def bounds_from_mapping(data: Any, chains: bool = True, joints: int = 3) -> Bounds:
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


def shared_sections(top: Mapping[str, Any], actuators: tuple[str, ...] = ACTUATOR_NAMES) -> dict[str, Any]:
    """The sections a crane file's and a machine file's study read alike: spline, tracking, solver, build, energy.

    ``actuators``: the study's actuator names (the keys of the energy section's transmission catalogue).
    """
    return {
        "spline": SplineSettings(**section(SplineSettings, top.get("spline"), "spline")),
        "tracking": Tracking(**section(Tracking, top.get("tracking"), "tracking")),
        "solver": SolverSettings(**section(SolverSettings, top.get("solver"), "solver")),
        "build": BuildSettings.from_mapping(top.get("build")),
        "energy": energy_settings(top, actuators),
    }


def work_sections(top: Mapping[str, Any], file: Source, names: ColumnNames) -> dict[str, Any]:
    """The study's name, recorded path, grid and tasks, read alike from a crane file's and a machine file's study.

    The name defaults to the study file's stem; the tasks' CSV paths resolve in its folder and a spiral's
    duration defaults to ``grid.duration`` [s]. ``names``: the machine's CSV column names
    (:func:`hiab_sim.study.spec.tasks.column_names`).
    """
    grid = GridSettings(**section(GridSettings, top.get("grid"), "grid"))
    name = str(top.get("name", Path(str(file.file)).stem))
    tasks = tasks_from_mapping(top, Path(str(file.file)).parent, grid.duration, name, names)
    return {"name": name, "path": recorded_path(file), "grid": grid, "tasks": tasks}

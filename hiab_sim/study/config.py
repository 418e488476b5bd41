"""Study YAML -> frozen dataclasses: crane, EMLAs, spline, grid, spiral reference, bounds, solver.

A study file names everything the optimiser of seed eqs. ``costf2`` / ``const_a``..``const_m``
needs; every unknown or missing key raises :class:`~hiab_sim.errors.ConfigError` and every
out-of-range value :class:`~hiab_sim.errors.InvalidInputError` naming the field. Relative file
paths in a study (crane, EMLA) are resolved against the study file's folder.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hiab_sim.config import CHAIN_NAMES, CRANE_PRESETS, ChainLengths, Crane, LinkLengths, load_crane
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.yaml_fields import mapping, number, positive, read_yaml

#: Folder of the shipped studies (``optimize/`` at the repository root).
STUDY_DIR = Path(__file__).resolve().parents[2] / "optimize"
DEFAULT_STUDY = STUDY_DIR / "xs031_spiral.yaml"
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
class SpiralReference:
    """TCP spiral in the vertical plane of {W} with a prescribed telescope schedule.

    The TCP goes around ``centre`` with a radius growing linearly from ``start_radius`` to
    ``end_radius`` over ``turns`` turns; the path parameter follows the rest-to-rest quintic
    s(t) = 10 tau^3 - 15 tau^4 + 6 tau^5 (tau = t / duration), so velocity and acceleration are
    zero at both ends. The telescope follows xt2(t) = ``telescope_start`` +
    ``telescope_amplitude`` sin(pi s(t)) (out and back). Exactly one of ``centre_joints``
    (theta1, theta2) [rad] at xt2 = ``telescope_start``, or ``centre_tcp`` (x, y) [m] is given.
    """

    start_radius: float
    end_radius: float
    turns: float
    start_angle: float
    telescope_start: float
    telescope_amplitude: float
    centre_joints: tuple[float, float] | None = None
    centre_tcp: tuple[float, float] | None = None


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
    joint_velocity: tuple[float, float, float] = (0.6, 0.6, 0.5)
    triangle_margin: float = math.radians(10.0)
    working_margin: float = math.radians(3.0)
    envelope_margin: float = 0.02
    working_range: str = "crane"


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

    """

    maxiter: int = 100
    ftol: float = 1e-9
    id_path: str = "mujoco"
    fd_step: float = 1e-6
    xi_derivatives: str = "analytic"


@dataclass(frozen=True)
class Study:
    """Everything one optimisation needs (see module docstring)."""

    name: str
    path: str
    crane_source: str
    crane: Crane = field(repr=False)
    emla_source: str | None
    initial_lengths: LinkLengths
    spline: SplineSettings
    grid: GridSettings
    reference: SpiralReference
    tracking: Tracking
    bounds: Bounds
    solver: SolverSettings
    payload: float = 0.0  # kg hanging at the TCP

    @property
    def tcp_force(self) -> np.ndarray | None:
        """Force of the payload on the TCP in {W} [N], or None without payload."""
        if self.payload == 0.0:
            return None
        return np.array([0.0, -self.payload * self.crane.gravity, 0.0])


_TOP = {
    "name",
    "crane",
    "emla",
    "initial_lengths",
    "spline",
    "grid",
    "reference",
    "tracking",
    "bounds",
    "solver",
    "payload",
}
_REQUIRED_TOP = {"crane", "reference", "bounds"}


def load_study(path: str | Path | None = None) -> Study:
    """Load and validate a study YAML file (default: ``optimize/xs031_spiral.yaml``).

    Raises:
        ConfigError: Missing file, malformed YAML, unknown or missing keys, wrong types.
        InvalidInputError: A value out of range, named by its field.

    """
    file = DEFAULT_STUDY if path is None else Path(path)
    return study_from_dict(read_yaml(file, "study"), file)


def study_from_dict(data: Any, file: str | Path = "<study>") -> Study:
    """Build a :class:`Study` from a parsed YAML mapping (relative paths resolve next to ``file``)."""
    file = Path(file)
    top = mapping(data, "study", _TOP, _REQUIRED_TOP)
    crane_source = str(top["crane"])
    crane_path = crane_source if crane_source in CRANE_PRESETS else str(_resolve(crane_source, file))
    crane = load_crane(crane_path)
    emla = top.get("emla")
    emla_source = None if emla in (None, "default") else str(_resolve(str(emla), file))
    if emla_source is not None and not Path(emla_source).is_file():
        raise ConfigError(f"emla: no such EMLA file {emla_source}")
    initial = _lengths(top.get("initial_lengths"), crane)
    spline_d = mapping(top.get("spline", {}), "spline", {"control_points", "degree"}, set())
    spline = SplineSettings(
        control_points=_integer(spline_d.get("control_points", 22), "spline.control_points", 6),
        degree=_integer(spline_d.get("degree", 5), "spline.degree", 3),
    )
    if spline.degree > 7:
        raise InvalidInputError("spline.degree", spline.degree, "must lie in [3, 7]")
    if spline.control_points < spline.degree + 2:
        raise InvalidInputError(
            "spline.control_points", spline.control_points, f"must be >= degree + 2 = {spline.degree + 2}"
        )
    grid_d = mapping(top.get("grid", {}), "grid", {"duration", "intervals", "fine_factor"}, set())
    grid = GridSettings(
        duration=positive(grid_d.get("duration", 6.25), "grid.duration", "s"),
        intervals=_integer(grid_d.get("intervals", 25), "grid.intervals", 2),
        fine_factor=_integer(grid_d.get("fine_factor", 10), "grid.fine_factor", 1),
    )
    reference = _reference(top["reference"])
    track_keys = {"position", "velocity", "acceleration", "collocation_fraction"}
    track_d = mapping(top.get("tracking", {}), "tracking", track_keys, set())
    tracking = Tracking(
        position=positive(track_d.get("position", 1e-3), "tracking.position", "m"),
        velocity=positive(track_d.get("velocity", 5e-3), "tracking.velocity", "m/s"),
        acceleration=positive(track_d.get("acceleration", 5e-2), "tracking.acceleration", "m/s^2"),
        collocation_fraction=positive(track_d.get("collocation_fraction", 0.5), "tracking.collocation_fraction"),
    )
    if tracking.collocation_fraction > 1.0:
        raise InvalidInputError("tracking.collocation_fraction", tracking.collocation_fraction, "must lie in (0, 1]")
    bounds = _bounds(top["bounds"], initial)
    solver_keys = {"maxiter", "ftol", "id_path", "fd_step", "xi_derivatives"}
    solver_d = mapping(top.get("solver", {}), "solver", solver_keys, set())
    xi_derivatives = str(solver_d.get("xi_derivatives", "analytic"))
    if xi_derivatives not in ("analytic", "rebuild"):
        raise InvalidInputError("solver.xi_derivatives", xi_derivatives, "must be 'analytic' or 'rebuild'")
    id_path = str(solver_d.get("id_path", "mujoco"))
    if id_path not in ID_PATHS:
        raise InvalidInputError("solver.id_path", id_path, f"must be one of {', '.join(ID_PATHS)}")
    solver = SolverSettings(
        maxiter=_integer(solver_d.get("maxiter", 100), "solver.maxiter", 1),
        ftol=positive(solver_d.get("ftol", 1e-9), "solver.ftol"),
        id_path=id_path,
        fd_step=positive(solver_d.get("fd_step", 1e-6), "solver.fd_step"),
        xi_derivatives=xi_derivatives,
    )
    payload = number(top.get("payload", 0.0), "payload")
    if payload < 0.0:
        raise InvalidInputError("payload", payload, "must be >= 0", "kg")
    return Study(
        name=str(top.get("name", file.stem)),
        path=str(file),
        crane_source=crane_source,
        crane=crane,
        emla_source=emla_source,
        initial_lengths=initial,
        spline=spline,
        grid=grid,
        reference=reference,
        tracking=tracking,
        bounds=bounds,
        solver=solver,
        payload=payload,
    )


def _resolve(source: str, file: Path) -> Path:
    candidate = Path(source)
    if candidate.is_absolute() or candidate.exists():
        return candidate
    return (file.parent / candidate).resolve()


def _lengths(data: Any, crane: Crane) -> LinkLengths:
    if data is None:
        return crane.default_lengths
    top = mapping(data, "initial_lengths", set(CHAIN_NAMES), set(CHAIN_NAMES))
    chains = []
    for name in CHAIN_NAMES:
        d = mapping(top[name], f"initial_lengths.{name}", {"L", "Lc0", "Lc"}, {"L", "Lc0", "Lc"})
        values = [positive(d[k], f"initial_lengths.{name}.{k}", "m") for k in ("L", "Lc0", "Lc")]
        chains.append(ChainLengths(*values))
    return LinkLengths(chains[0], chains[1])


def _reference(data: Any) -> SpiralReference:
    keys = {
        "centre_joints",
        "centre_tcp",
        "start_radius",
        "end_radius",
        "turns",
        "start_angle",
        "telescope_start",
        "telescope_amplitude",
    }
    required = keys - {"centre_joints", "centre_tcp", "start_angle", "telescope_amplitude"}
    d = mapping(data, "reference", keys, required)
    if ("centre_joints" in d) == ("centre_tcp" in d):
        raise ConfigError("reference: give exactly one of centre_joints [theta1, theta2] or centre_tcp [x, y]")
    centre_key = "centre_joints" if "centre_joints" in d else "centre_tcp"
    centre = _pair(d[centre_key], f"reference.{centre_key}")
    r0 = number(d["start_radius"], "reference.start_radius")
    r1 = positive(d["end_radius"], "reference.end_radius", "m")
    if r0 < 0.0:
        raise InvalidInputError("reference.start_radius", r0, "must be >= 0", "m")
    turns = number(d["turns"], "reference.turns")
    if turns == 0.0 or abs(turns) > 10.0:
        raise InvalidInputError("reference.turns", turns, "must be nonzero with |turns| <= 10")
    tele = number(d["telescope_start"], "reference.telescope_start")
    if tele < 0.0:
        raise InvalidInputError("reference.telescope_start", tele, "must be >= 0", "m")
    return SpiralReference(
        start_radius=r0,
        end_radius=r1,
        turns=turns,
        start_angle=number(d.get("start_angle", 0.0), "reference.start_angle"),
        telescope_start=tele,
        telescope_amplitude=number(d.get("telescope_amplitude", 0.0), "reference.telescope_amplitude"),
        centre_joints=centre if centre_key == "centre_joints" else None,
        centre_tcp=centre if centre_key == "centre_tcp" else None,
    )


def _bounds(data: Any, initial: LinkLengths) -> Bounds:
    keys = {
        "lift",
        "tilt",
        "joint_velocity",
        "triangle_margin_deg",
        "working_range",
        "working_margin_deg",
        "envelope_margin",
    }
    d = mapping(data, "bounds", keys, {"lift", "tilt"})
    low: list[float] = []
    up: list[float] = []
    for name in CHAIN_NAMES:
        chain = mapping(d[name], f"bounds.{name}", {"low", "up"}, {"low", "up"})
        lo = _triple(chain["low"], f"bounds.{name}.low")
        hi = _triple(chain["up"], f"bounds.{name}.up")
        for i, key in enumerate(("L", "Lc0", "Lc")):
            if not 0.0 < lo[i] < hi[i]:
                raise InvalidInputError(
                    f"bounds.{name}.low[{i}] ({key})", lo[i], f"must satisfy 0 < low < up = {hi[i]:.6g}", "m"
                )
            start = getattr(getattr(initial, name), key)
            if not lo[i] <= start <= hi[i]:
                raise InvalidInputError(
                    f"initial_lengths.{name}.{key}", start, f"must lie in the bounds [{lo[i]:.6g}, {hi[i]:.6g}]", "m"
                )
        low += lo
        up += hi
    velocity = _triple(d.get("joint_velocity", [0.6, 0.6, 0.5]), "bounds.joint_velocity")
    if min(velocity) <= 0.0:
        raise InvalidInputError("bounds.joint_velocity", min(velocity), "every limit must be > 0")
    margin = number(d.get("triangle_margin_deg", 10.0), "bounds.triangle_margin_deg")
    if not 0.0 <= margin < 60.0:
        raise InvalidInputError("bounds.triangle_margin_deg", margin, "must lie in [0, 60)", "deg")
    working = number(d.get("working_margin_deg", 3.0), "bounds.working_margin_deg")
    if not 0.0 <= working <= 30.0:
        raise InvalidInputError("bounds.working_margin_deg", working, "must lie in [0, 30]", "deg")
    working_range = str(d.get("working_range", "crane"))
    if working_range not in ("crane", "reference"):
        raise InvalidInputError("bounds.working_range", working_range, "must be 'crane' or 'reference'")
    envelope = number(d.get("envelope_margin", 0.02), "bounds.envelope_margin")
    if not 0.0 <= envelope < 0.5:
        raise InvalidInputError("bounds.envelope_margin", envelope, "must lie in [0, 0.5)")
    return Bounds(
        tuple(low),
        tuple(up),
        (velocity[0], velocity[1], velocity[2]),
        math.radians(margin),
        math.radians(working),
        envelope,
        working_range,
    )


def _integer(value: Any, where: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(f"{where}: expected an integer, got {value!r}")
    if value < minimum:
        raise InvalidInputError(where, value, f"must be >= {minimum}")
    return int(value)


def _pair(value: Any, where: str) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ConfigError(f"{where}: expected a list of 2 numbers, got {value!r}")
    return (number(value[0], f"{where}[0]"), number(value[1], f"{where}[1]"))


def _triple(value: Any, where: str) -> list[float]:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ConfigError(f"{where}: expected a list of 3 numbers, got {value!r}")
    return [number(v, f"{where}[{i}]") for i, v in enumerate(value)]

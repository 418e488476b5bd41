"""Reference kinds of a task: what the TCP and the telescope must do, sampled at any times.

Every kind is a frozen dataclass, validated when built, with a ``duration`` [s] and
``sample(kin, times) -> Reference``: r = (x_tcp, y_tcp, xt2) in the vertical plane of {W}
(y up) with its first two time derivatives, each (T, 3) [m, m/s, m/s^2]. The NLP tracks r within
the tolerance bands (eqs. ``const_b``..``const_d``); its initial spline comes from inverse
kinematics of r started at :func:`initial_joints`.

* :class:`Spiral`: today's spiral (the fields of ``study.config.SpiralReference`` and the numbers of
  ``trajectory.spiral_reference``, moved here). Telescope: prescribed, out and back,
  xt2 = xt0 + a sin(pi s(t)).
* :class:`PickAndPlace`: rest to rest from a pick point to a place point over an obstacle.
  The path is the cubic Bezier curve with control points pick, (x_pick, h), (x_place, h), place:
  it leaves the pick point vertically, moves over, comes down vertically onto the place point,
  x is monotone between them, and h is solved so that the curve's highest point is exactly at
  the ``clearance`` height. The path parameter s(t) follows the rest-to-rest septic
  s = 35 tau^4 - 84 tau^5 + 70 tau^6 - 20 tau^7, whose velocity, acceleration and jerk vanish at
  both ends, so the reference is C^3 across the dwells at pick and place (the quintic spline of
  the NLP, C^4, can follow it; the quintic law would leave a jump in jerk there). Telescope:
  prescribed, xt2 = xt_pick + (xt_place - xt_pick) s(t) with the same law, so it starts and
  stops with the booms and rests during the dwells.
* ``csv`` (:mod:`hiab_sim.study.references.csv_file`): a recorded or planned trajectory file.

Why the telescope is prescribed for every kind: the crane has three joints for a planar TCP
point, and the NLP tracks r = (x, y, xt2). A prescribed xt2 makes the inverse kinematics unique
(two-link arm, :mod:`hiab_sim.study.motion.workspace`), keeps the reference reachable by construction
(checked here before any optimisation), and states the task as an operator runs it: the
telescope out to reach far, in near the base. Resolving xt2 by the optimiser instead would drop
the xt2 rows of const_b..const_d and let the optimum trade telescope motion for boom motion; it
is a different task, not a better-solved one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

import numpy as np
from scipy.optimize import brentq

from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.motion.trajectory import Reference, timing_law
from hiab_sim.study.motion.workspace import check_workspace, dense_times, initial_joints

if TYPE_CHECKING:
    from hiab_sim.crane.description import Crane
    from hiab_sim.study.machines.protocol import Kinematics, StudyMachine
from hiab_sim.arrays import Array
from hiab_sim.study.references.csv_file import ColumnNames, CsvReference
from hiab_sim.yaml_fields import mapping, number, positive

KINDS = ("spiral", "pick_and_place", "csv")


class TaskReference(Protocol):
    """What the NLP needs of a reference kind."""

    kind: ClassVar[str]

    @property
    def duration(self) -> float:
        """Length of the task [s]; the task's grid spans [0, duration]."""

    def sample(self, kin: Kinematics, times: Array) -> Reference:
        """Reference r = (x_tcp, y_tcp, xt2) and its rates at ``times`` [s], each (T, 3)."""

    def check_reach(self, kin: Kinematics, model: StudyMachine | Crane) -> None:
        """Raise :class:`InvalidInputError` naming the first time (or file row) the machine cannot reach."""


def septic_law(times: Array, start: float, duration: float) -> tuple[Array, Array, Array]:
    """Rest-to-rest septic s(t) from 0 at ``start`` to 1 at ``start + duration`` and ds/dt, d2s/dt2.

    s = 35 tau^4 - 84 tau^5 + 70 tau^6 - 20 tau^7, tau = (t - start) / duration clipped to [0, 1];
    ds/dtau = 140 tau^3 (1 - tau)^3, d2s/dtau2 = 420 tau^2 (1 - tau)^2 (1 - 2 tau).
    """
    tau = np.clip((np.asarray(times, dtype=float) - start) / duration, 0.0, 1.0)
    s = tau**4 * (35.0 - 84.0 * tau + 70.0 * tau**2 - 20.0 * tau**3)
    ds = 140.0 * tau**3 * (1.0 - tau) ** 3 / duration
    dds = 420.0 * tau**2 * (1.0 - tau) ** 2 * (1.0 - 2.0 * tau) / duration**2
    return s, ds, dds


# ---------------------------------------------------------------------------------------------
# spiral
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Spiral:
    """TCP spiral in the vertical plane of {W} with a prescribed telescope schedule, over ``duration`` [s].

    The fields and numbers of today's ``SpiralReference`` / ``trajectory.spiral_reference`` (moved
    here so that this module does not import the study loader). The TCP goes around ``centre``
    with a radius growing linearly from ``start_radius`` to ``end_radius`` [m] over ``turns``
    turns from ``start_angle`` [rad]; the path parameter follows the rest-to-rest quintic
    s = 10 tau^3 - 15 tau^4 + 6 tau^5 (tau = t / duration). The telescope follows
    xt2 = ``telescope_start`` + ``telescope_amplitude`` sin(pi s) [m]. Exactly one of
    ``centre_joints`` (theta1, theta2) [rad] at xt2 = ``telescope_start``, or ``centre_tcp``
    (x, y) [m] is given.
    """

    start_radius: float
    end_radius: float
    turns: float
    telescope_start: float
    duration: float
    start_angle: float = 0.0
    telescope_amplitude: float = 0.0
    centre_joints: tuple[float, float] | None = None
    centre_tcp: tuple[float, float] | None = None
    kind: ClassVar[str] = "spiral"

    def __post_init__(self) -> None:
        _check(self.duration > 0.0, "reference.duration", self.duration, "must be > 0", "s")
        if (self.centre_joints is None) == (self.centre_tcp is None):
            raise ConfigError("reference: give exactly one of centre_joints [theta1, theta2] or centre_tcp [x, y]")
        _check(self.start_radius >= 0.0, "reference.start_radius", self.start_radius, "must be >= 0", "m")
        _check(self.end_radius > 0.0, "reference.end_radius", self.end_radius, "must be > 0", "m")
        _check(
            self.turns != 0.0 and abs(self.turns) <= 10.0,
            "reference.turns",
            self.turns,
            "must be nonzero, |turns| <= 10",
        )
        _check(self.telescope_start >= 0.0, "reference.telescope_start", self.telescope_start, "must be >= 0", "m")

    def centre(self, kin: Kinematics) -> tuple[float, float]:
        """Spiral centre in {W} (x, y) [m]: given, or the TCP at the given centre joints."""
        if self.centre_tcp is not None:
            return self.centre_tcp
        assert self.centre_joints is not None
        p = kin.position(np.array([[*self.centre_joints, self.telescope_start]]))[0]
        return float(p[0]), float(p[1])

    def sample(self, kin: Kinematics, times: Array) -> Reference:
        """Reference r = (x, y, xt2) of the spiral and its rates at ``times`` [s]."""
        s, ds, dds = timing_law(times, self.duration)
        cx, cy = self.centre(kin)
        omega = 2.0 * np.pi * self.turns
        phi = self.start_angle + omega * s
        dr = self.end_radius - self.start_radius
        r = self.start_radius + dr * s
        radial = np.column_stack([np.cos(phi), np.sin(phi)])
        tangent = np.column_stack([-np.sin(phi), np.cos(phi)])
        p_s = dr * radial + (r * omega)[:, None] * tangent
        p_ss = 2.0 * dr * omega * tangent - (r * omega**2)[:, None] * radial
        xy = np.array([cx, cy]) + r[:, None] * radial
        v = p_s * ds[:, None]
        a = p_ss * (ds**2)[:, None] + p_s * dds[:, None]
        amp = self.telescope_amplitude
        xt = self.telescope_start + amp * np.sin(np.pi * s)
        dxt = amp * np.pi * np.cos(np.pi * s) * ds
        ddxt = -amp * np.pi**2 * np.sin(np.pi * s) * ds**2 + amp * np.pi * np.cos(np.pi * s) * dds
        return Reference(
            time=np.asarray(times, dtype=float),
            position=np.column_stack([xy, xt]),
            velocity=np.column_stack([v, dxt]),
            acceleration=np.column_stack([a, ddxt]),
            z=kin.z,
            centre=(cx, cy),
        )

    def check_reach(self, kin: Kinematics, model: StudyMachine | Crane) -> None:
        """The machine's IK of the reference every <= 10 ms; raises naming the first unreachable time."""
        check_workspace(model, self.sample(kin, dense_times(self.duration)))

    @classmethod
    def from_mapping(cls, data: Any, where: str, default_duration: float) -> Spiral:
        """Read today's ``reference:`` keys plus an optional ``duration`` [s] (default: the grid's)."""
        keys = {"kind", "duration", "centre_joints", "centre_tcp", "start_radius", "end_radius", "turns"}
        keys |= {"start_angle", "telescope_start", "telescope_amplitude"}
        required = {"start_radius", "end_radius", "turns", "telescope_start"}
        d = mapping(data, where, keys, required)
        centre = {key: _pair(d[key], f"{where}.{key}") for key in ("centre_joints", "centre_tcp") if key in d}
        return cls(
            start_radius=number(d["start_radius"], f"{where}.start_radius"),
            end_radius=number(d["end_radius"], f"{where}.end_radius"),
            turns=number(d["turns"], f"{where}.turns"),
            telescope_start=number(d["telescope_start"], f"{where}.telescope_start"),
            duration=positive(d.get("duration", default_duration), f"{where}.duration", "s"),
            start_angle=number(d.get("start_angle", 0.0), f"{where}.start_angle"),
            telescope_amplitude=number(d.get("telescope_amplitude", 0.0), f"{where}.telescope_amplitude"),
            centre_joints=centre.get("centre_joints"),
            centre_tcp=centre.get("centre_tcp"),
        )


# ---------------------------------------------------------------------------------------------
# pick and place
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PickAndPlace:
    """TCP rest to rest from ``pick`` to ``place`` over ``clearance``, with dwells (module docstring).

    Attributes:
        pick: TCP (x, y) in {W} where the load is picked [m].
        place: TCP (x, y) in {W} where it is set down [m].
        clearance: Height y in {W} of the path's highest point [m], above both end points.
        telescope: xt2 at pick and at place [m].
        move_time: Duration of the move [s].
        dwell: Rest at the pick point before the move and at the place point after it [s].

    """

    pick: tuple[float, float]
    place: tuple[float, float]
    clearance: float
    telescope: tuple[float, float]
    move_time: float
    dwell: tuple[float, float] = (1.0, 1.0)
    kind: ClassVar[str] = "pick_and_place"

    def __post_init__(self) -> None:
        top = max(self.pick[1], self.place[1])
        _check(self.clearance > top, "reference.clearance", self.clearance, f"must be > {top:.6g} (pick, place y)", "m")
        _check(self.move_time > 0.0, "reference.move_time", self.move_time, "must be > 0", "s")
        for i, value in enumerate(self.dwell):
            _check(value >= 0.0, f"reference.dwell[{i}]", value, "must be >= 0", "s")
        for i, value in enumerate(self.telescope):
            _check(value >= 0.0, f"reference.telescope[{i}]", value, "must be >= 0", "m")

    @property
    def duration(self) -> float:
        """Dwell at pick + move + dwell at place [s]."""
        return self.dwell[0] + self.move_time + self.dwell[1]

    def control_height(self) -> float:
        """Height h of the two inner Bezier control points that puts the apex at ``clearance`` [m]."""
        y0, y3, top = self.pick[1], self.place[1], self.clearance
        # y(s) = (1-s)^3 y0 + 3 s (1-s) h + s^3 y3: the weights sum to 1, so h = top gives max y < top,
        # and y(1/2) = (y0 + y3)/8 + 3h/4 = top at h = (8 top - y0 - y3)/6; the apex grows with h.
        upper = (8.0 * top - y0 - y3) / 6.0
        if _apex(y0, y3, upper) <= top:  # symmetric ends: the apex is y(1/2), at top to round-off
            return float(upper)
        return float(brentq(lambda h: _apex(y0, y3, h) - top, top, upper, xtol=1e-14))

    def path(self, s: Array) -> tuple[Array, Array, Array]:
        """Bezier point P(s), dP/ds and d2P/ds2, each (T, 2) [m]."""
        h = self.control_height()
        p0, p3 = np.array(self.pick), np.array(self.place)
        p1, p2 = np.array([p0[0], h]), np.array([p3[0], h])
        s = np.asarray(s, dtype=float)[:, None]
        r = 1.0 - s
        point = r**3 * p0 + 3.0 * r**2 * s * p1 + 3.0 * r * s**2 * p2 + s**3 * p3
        tangent = 3.0 * (r**2 * (p1 - p0) + 2.0 * r * s * (p2 - p1) + s**2 * (p3 - p2))
        curvature = 6.0 * (r * (p2 - 2.0 * p1 + p0) + s * (p3 - 2.0 * p2 + p1))
        return point, tangent, curvature

    def sample(self, kin: Kinematics, times: Array) -> Reference:
        """Reference r = (x, y, xt2) and its rates: P(s(t)), P' ds, P'' ds^2 + P' dds; xt2 with the same s(t)."""
        t = np.asarray(times, dtype=float)
        s, ds, dds = septic_law(t, self.dwell[0], self.move_time)
        point, tangent, curvature = self.path(s)
        velocity = tangent * ds[:, None]
        acceleration = curvature * (ds**2)[:, None] + tangent * dds[:, None]
        stroke = self.telescope[1] - self.telescope[0]
        return Reference(
            time=t,
            position=np.column_stack([point, self.telescope[0] + stroke * s]),
            velocity=np.column_stack([velocity, stroke * ds]),
            acceleration=np.column_stack([acceleration, stroke * dds]),
            z=kin.z,
            centre=self.pick,
        )

    def check_reach(self, kin: Kinematics, model: StudyMachine | Crane) -> None:
        """The machine's IK of the reference every <= 10 ms; raises naming the first unreachable time."""
        check_workspace(model, self.sample(kin, dense_times(self.duration)))

    @classmethod
    def from_mapping(cls, data: Any, where: str) -> PickAndPlace:
        """Read ``{kind, pick, place, clearance, telescope, move_time, dwell}`` (dwell optional)."""
        keys = {"kind", "pick", "place", "clearance", "telescope", "move_time", "dwell"}
        d = mapping(data, where, keys, keys - {"dwell"})
        dwell = _pair(d.get("dwell", [1.0, 1.0]), f"{where}.dwell")
        return cls(
            pick=_pair(d["pick"], f"{where}.pick"),
            place=_pair(d["place"], f"{where}.place"),
            clearance=number(d["clearance"], f"{where}.clearance"),
            telescope=_pair(d["telescope"], f"{where}.telescope"),
            move_time=number(d["move_time"], f"{where}.move_time"),
            dwell=dwell,
        )


def _apex(y0: float, y3: float, h: float) -> float:
    """Highest y of the cubic Bezier with control heights y0, h, h, y3 over s in [0, 1]."""
    # dy/ds / 3 = (y3 - y0) s^2 + 2 (y0 - h) s + (h - y0)
    roots = np.roots([y3 - y0, 2.0 * (y0 - h), h - y0]) if y3 != y0 else np.array([0.5])
    s = np.concatenate([[0.0, 1.0], roots[np.isreal(roots)].real])
    s = s[(s >= 0.0) & (s <= 1.0)]
    return float(np.max((1 - s) ** 3 * y0 + 3.0 * s * (1 - s) * h + s**3 * y3))


# ---------------------------------------------------------------------------------------------
# shared: loading, reachability, the inverse-kinematics start
# ---------------------------------------------------------------------------------------------


def reference_from_mapping(
    data: Any,
    where: str,
    folder: Path,
    default_duration: float,
    names: ColumnNames,
) -> TaskReference:
    """Build the reference kind named by ``kind`` (default ``spiral``: today's single reference).

    Args:
        data: The parsed ``reference:`` mapping.
        where: Its dotted path for messages, e.g. ``tasks[1].reference``.
        folder: Folder of the study file (relative CSV paths resolve there).
        default_duration: The grid's duration [s], used by a spiral without ``duration``.
        names: The machine's tracked coordinates beyond the TCP's x, y, and its joints (a CSV's columns).

    """
    kind = str(mapping(data, where, None).get("kind", "spiral"))
    if kind == "spiral":
        return Spiral.from_mapping(data, where, default_duration)
    if kind == "pick_and_place":
        return PickAndPlace.from_mapping(data, where)
    if kind == "csv":
        return CsvReference.from_mapping(data, where, folder, names)
    raise InvalidInputError(f"{where}.kind", kind, f"must be one of {', '.join(KINDS)}")


def ik_start(reference: TaskReference, model: StudyMachine, sampled: Reference) -> Array:
    """Joints (n,) that start the Newton IK of ``sampled`` (the crane reads its first two).

    A spiral's ``centre_joints`` (today's start), or the middle of the joint ranges for a spiral
    given by its TCP centre (the prescribed joints at their first sample); any other kind: the
    machine's IK of its first sample (:meth:`~hiab_sim.study.machines.protocol.StudyMachine.ik_guess`).
    """
    if isinstance(reference, Spiral):
        first = sampled.position[0]
        if reference.centre_joints is not None:
            return np.array([*reference.centre_joints, *first[2:]])
        (lo1, hi1), (lo2, hi2) = model.joint_ranges()[:2]
        return np.array([0.5 * (lo1 + hi1), 0.5 * (lo2 + hi2), *first[2:]])
    return model.ik_guess(sampled.position[0])


def _check(ok: bool, field: str, value: float, allowed: str, unit: str = "") -> None:
    if not ok or (isinstance(value, float) and not math.isfinite(value)):
        raise InvalidInputError(field, value, allowed, unit)


def _pair(value: Any, where: str) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ConfigError(f"{where}: expected a list of 2 numbers, got {value!r}")
    return (number(value[0], f"{where}[0]"), number(value[1], f"{where}[1]"))


__all__ = [
    "KINDS",
    "PickAndPlace",
    "Spiral",
    "TaskReference",
    "check_workspace",
    "ik_start",
    "initial_joints",
    "reference_from_mapping",
    "septic_law",
]

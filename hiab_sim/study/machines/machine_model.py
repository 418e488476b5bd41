"""Any machine file (:mod:`hiab_sim.machine`) as a :class:`~hiab_sim.study.machines.protocol.StudyMachine`.

Names, joints, chains and decision variables come from the file; nothing here spells a machine's.

* Kinematics: :class:`hiab_sim.machine.kinematics.tracked.TrackedKinematics`, tracked coordinates
  r = (x_tcp, y_tcp, *extra), each extra a joint (prescribed, as the crane's telescope) or
  ``tcp_angle`` (the TCP frame's attitude in the plane, e.g. a bucket's).
* Inverse dynamics: ``analytic`` is the planar Newton-Euler on the link tree with the loop
  constraints (:mod:`hiab_sim.machine.dynamics.newton_euler`), ``mujoco`` the MJCF regenerated per
  design with ``mj_inverse`` and the loop projection (:mod:`hiab_sim.machine.dynamics.mujoco_path`);
  both independent of each other and equal to round-off.
* Strokes: every ``triangle`` or ``linkage`` chain has stroke rows, x = s(q_j) - x0 from its loop
  closure (:mod:`hiab_sim.machine.kinematics.closure`) with exact partials in q and in the
  decision variables (:mod:`hiab_sim.machine.kinematics.design_partials`); a ``direct`` chain's
  stroke is its joint, bounded by the joint's range.
* Joint bounds: each joint's working range (a triangle's flat-triangle margin of the crane has no
  counterpart here: the machine file's ranges are the usable ones, checked by ``machine check``).
* Decision variables and their bounds: the file's.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples
from hiab_sim.errors import InvalidInputError
from hiab_sim.hydraulics.cylinders import HydraulicSystem
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import MachineDesign
from hiab_sim.machine.dynamics.newton_euler import batched_inverse_dynamics
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.machine.kinematics.closure import joint_to_stroke, stroke_to_joint
from hiab_sim.machine.kinematics.tracked import TrackedKinematics
from hiab_sim.machine.kinematics.tracked import inverse_kinematics as tracked_ik
from hiab_sim.study.machines.machine_strokes import StrokeRows, chains_with_strokes
from hiab_sim.study.machines.protocol import PointReach
from hiab_sim.study.motion import trajectory as tr

#: The study's inverse-dynamics path names and the machine's.
PATHS = {"analytic": "newton_euler", "mujoco": "mujoco"}
#: What each :attr:`PointReach.status` code means, for error messages.
REASONS = (
    "reachable",
    "is out of the machine's reach (inverse kinematics did not converge)",
    "needs a joint outside its working range",
    "needs an actuator stroke outside [0, stroke]",
)
#: Start points per joint of the IK of a first sample (a grid over each joint's range).
GUESSES_PER_JOINT = 5
#: Slack on the stroke and range checks of reachable points [m or rad]: round-off of the IK.
REACH_TOLERANCE = 1e-9


#: The decision variables' bounds the inverse dynamics accepts, widened by this share of their span at both ends:
#: the bounds are the NLP's (SLSQP's trial points and the finite differences may step past them by round-off).
BOUND_SLACK = 0.25


def unbounded(machine: Machine) -> Machine:
    """The machine with its decision variables' bounds widened by :data:`BOUND_SLACK` of their span."""
    chains = []
    for chain in machine.chains:
        variables = tuple(
            replace(v, low=v.low - BOUND_SLACK * (v.high - v.low), high=v.high + BOUND_SLACK * (v.high - v.low))
            for v in chain.variables
        )
        chains.append(replace(chain, variables=variables))
    return replace(machine, chains=tuple(chains))


class MachineDynamics:
    """The study's inverse-dynamics callable on a machine path: joint samples in, actuator samples out."""

    def __init__(self, machine: Machine, design: Array, path: str) -> None:
        self.model = make_machine_dynamics(machine, [float(x) for x in design], PATHS[path])

    def __call__(self, joints: JointSamples, tcp_force: ArrayLike | None = None) -> ActuatorSamples:
        """[f_x, v_x, a_x] (T, n actuators) for joint samples; ``tcp_force`` [N] (3,) or (T, 3) in the world."""
        force = None if tcp_force is None else np.asarray(tcp_force, dtype=float)[..., :2]
        # the study needs no pin forces: a path that can leave them out is asked to
        skip = {"pins": False} if getattr(self.model, "can_skip_pins", False) else {}
        out = self.model(joints.position, joints.velocity, joints.acceleration, tcp_force=force, **skip)
        return ActuatorSamples(out.force, out.velocity, out.acceleration, out.stroke)


@dataclass(frozen=True)
class MachineModel:
    """A machine file as the study's machine (module docstring).

    Args:
        machine: The machine description.
        extra: Tracked coordinates beyond the TCP's x and y (n - 2 names: joints or ``tcp_angle``).

    """

    machine: Machine
    extra: tuple[str, ...]
    kinematics: TrackedKinematics = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "kinematics", TrackedKinematics(self.machine, self.extra))
        object.__setattr__(self, "_dynamics_machine", unbounded(self.machine))
        object.__setattr__(self, "_strokes", StrokeRows(self.machine, self.stroke_joints))

    @property
    def name(self) -> str:
        """The machine's name."""
        return self.machine.name

    @property
    def gravity(self) -> float:
        """[m/s^2]."""
        return self.machine.gravity

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The joints, in the file's link order."""
        return tuple(self.machine.joint_names)

    @property
    def joint_units(self) -> tuple[str, ...]:
        """``rad`` for a revolute joint, ``m`` for a prismatic one."""
        return tuple("rad" if self.machine.joint_link(j).joint_kind == "revolute" else "m" for j in self.joint_names)

    @property
    def actuator_names(self) -> tuple[str, ...]:
        """Each chain's EMLA name, in chain order (the order of actuator samples)."""
        return tuple(c.actuator.emla or c.name for c in self.machine.chains)

    @property
    def tracked_names(self) -> tuple[str, ...]:
        """(x_tcp, y_tcp, *extra)."""
        return tuple(self.kinematics.names)

    @property
    def design_names(self) -> tuple[str, ...]:
        """``chain.variable`` of every decision variable."""
        return tuple(self.machine.variable_keys)

    @property
    def stroke_chains(self) -> tuple[str, ...]:
        """The triangle and linkage chains."""
        return tuple(c.name for c in chains_with_strokes(self.machine))

    @property
    def stroke_joints(self) -> tuple[int, ...]:
        """Each stroke chain's joint index."""
        names = self.joint_names
        return tuple(names.index(c.joint) for c in chains_with_strokes(self.machine))

    @property
    def default_design(self) -> MachineDesign:
        """The file's values."""
        return self.design(self.machine.design_values())

    @property
    def hydraulic_cylinders(self) -> HydraulicSystem | None:
        """The hydraulic cylinders the EMLAs replace, in chain order, or None if a chain has none."""
        hyd = self.machine.hydraulic
        names = [c.actuator.hydraulic_cylinder for c in self.machine.chains]
        if hyd is None or any(n is None for n in names):
            return None
        return replace(hyd, cylinders=tuple(hyd.cylinder(str(n)) for n in names))

    def design(self, values: ArrayLike) -> MachineDesign:
        """The design with these values (n_xi,)."""
        v = np.asarray(values, dtype=float).reshape(-1)
        if v.shape != (len(self.design_names),):
            raise InvalidInputError("design", f"{v.size} values", f"need {len(self.design_names)}: {self.design_names}")
        return MachineDesign(self.design_names, tuple(float(x) for x in v))

    def design_bounds(self) -> tuple[Array, Array]:
        """The file's bounds of its decision variables."""
        low, up = self.machine.design_bounds()
        return np.asarray(low, dtype=float), np.asarray(up, dtype=float)

    def joint_ranges(self) -> tuple[tuple[float, float], ...]:
        """Every joint's working range [rad or m]."""
        out = []
        for j in self.joint_names:
            low, high = self.machine.joint_link(j).joint_range or (-np.inf, np.inf)
            out.append((float(low), float(high)))
        return tuple(out)

    def joint_bounds(self, triangle_margin: float) -> tuple[Array, Array]:
        """The joints' working ranges (the file's usable ranges; no triangle margin)."""
        ranges = np.array(self.joint_ranges(), dtype=float)
        return ranges[:, 0].copy(), ranges[:, 1].copy()

    def with_stroke_ranges(self, ranges: Sequence[tuple[float, float]]) -> MachineModel:
        """The machine with the stroke chains' joints' ranges replaced."""
        new = dict(zip((self.joint_names[j] for j in self.stroke_joints), ranges, strict=True))
        links = tuple(
            replace(link, joint_range=(float(new[link.joint][0]), float(new[link.joint][1])))
            if link.joint in new
            else link
            for link in self.machine.links
        )
        return MachineModel(replace(self.machine, links=links), self.extra)

    def _designed(self, design: Any) -> Machine:
        return self.machine.with_design(np.asarray(design.as_array()), check_bounds=False)  # the NLP holds the bounds

    def machine_at(self, design: Any) -> Machine:
        """The machine description with ``design``'s decision-variable values (bounds not checked: the NLP's)."""
        return self._designed(design)

    def buildable_ranges(
        self, stroke_margin: float, field: str = "build.stroke_margin"
    ) -> tuple[tuple[float, float], ...]:
        """Per stroke chain: q over which the file's design keeps ``stroke_margin`` [m] from both stroke ends.

        q(x = m) and q(x = stroke - m) by the closed-form inverse of the loop closure (either may be the
        larger: a chain's stroke may fall as its joint rises), intersected with the joint's range.
        """
        if not (np.isfinite(stroke_margin) and stroke_margin >= 0.0):
            raise InvalidInputError(field, stroke_margin, "must be a finite length >= 0", "m")
        ranges = self.joint_ranges()
        out = []
        for chain, j in zip(chains_with_strokes(self.machine), self.stroke_joints, strict=True):
            lo, hi = ranges[j]
            if stroke_margin == 0.0:
                out.append((lo, hi))
                continue
            if not 2.0 * stroke_margin < chain.actuator.stroke:
                raise InvalidInputError(
                    field, stroke_margin, f"must be < half the {chain.name} stroke {chain.actuator.stroke:.6g}", "m"
                )
            # strokes beyond those at the range's ends (where the loop may not close) give the range's end
            at_ends = joint_to_stroke(self.machine, chain, np.array([lo, hi]))
            ends = np.clip([stroke_margin, chain.actuator.stroke - stroke_margin], at_ends.min(), at_ends.max())
            q = np.sort(stroke_to_joint(self.machine, chain, ends))
            out.append((max(lo, float(q[0])), min(hi, float(q[1]))))
        return tuple(out)

    def inverse_dynamics(self, design: Any, path: str) -> MachineDynamics:
        """The machine's ``analytic`` (Newton-Euler) or ``mujoco`` inverse dynamics at this design."""
        if path not in PATHS:
            raise InvalidInputError("id_path", path, f"must be one of {', '.join(PATHS)}")
        return MachineDynamics(self.__dict__["_dynamics_machine"], np.asarray(design.as_array()), path)

    def design_partials(
        self, design: Any, joints: JointSamples, path: str, fd_step: float, tcp_force: ArrayLike | None
    ) -> Array:
        """d(f, v, a)/dXi (K, 3 n, n_xi) by central differences.

        The analytic path stacks the 2 n_xi designs into one Newton-Euler call
        (:func:`~hiab_sim.machine.dynamics.newton_euler.batched_inverse_dynamics`); ``mujoco`` builds one
        model per perturbed design.
        """
        xi = np.asarray(design.as_array(), dtype=float)
        machine = self.__dict__["_dynamics_machine"]
        if path == "analytic":
            h = fd_step * np.maximum(1.0, np.abs(xi))
            designs = np.repeat(xi[None], 2 * len(xi), axis=0)
            designs[0::2] += np.diag(h)
            designs[1::2] -= np.diag(h)
            force = None if tcp_force is None else np.asarray(tcp_force, dtype=float)[..., :2]
            f, v, a, _ = batched_inverse_dynamics(
                machine, designs, joints.position, joints.velocity, joints.acceleration, force
            )
            y = np.concatenate([f, v, a], axis=2)  # (2 n_xi, K, 3 n)
            d = (y[0::2] - y[1::2]) / (2.0 * h[:, None, None])
            return np.transpose(d, (1, 2, 0))
        out = np.zeros((len(joints), 3 * len(self.actuator_names), len(xi)))
        for i in range(len(xi)):
            h = fd_step * max(1.0, abs(xi[i]))
            values = []
            for sign in (1.0, -1.0):
                x = xi.copy()
                x[i] += sign * h
                act = MachineDynamics(machine, x, path)(joints, tcp_force=tcp_force)
                values.append(np.concatenate([act.force, act.velocity, act.acceleration], axis=1))
            out[:, :, i] = (values[0] - values[1]) / (2.0 * h)
        return out

    def stroke_margins(self, design: Any, q: Array) -> Array:
        """x, Lc - x, stroke - x per stroke chain [m], (K, 3 m).

        Built by :class:`~hiab_sim.study.machines.machine_strokes.StrokeRows` (chains and partials cached).
        """
        return self.__dict__["_strokes"].margins(design, q)

    def stroke_margin_partials(self, design: Any, q: Array) -> tuple[Array, Array]:
        """Exact partials of :meth:`stroke_margins` w.r.t. q (K, 3 m, n) and Xi (K, 3 m, n_xi)."""
        return self.__dict__["_strokes"].partials(design, q)

    # -- inverse kinematics ---------------------------------------------------------------

    def _newton(self, target: Array, guess: Array) -> Array | None:
        """Joints (n,) with r(q) = target by Newton from ``guess``, or None when it does not converge."""
        kin, q = self.kinematics, np.array(guess, dtype=float)
        n = len(q)
        zero = np.zeros((1, n))
        for _ in range(50):
            s = kin.samples(q[None], zero, zero)
            residual = s.position[0] - target
            if np.max(np.abs(residual)) < 1e-12:
                return q
            jac = s.d_position[0, :, :n]
            if abs(np.linalg.det(jac)) < 1e-12:
                return None
            q = q - np.clip(np.linalg.solve(jac, residual), -0.2, 0.2)
        return None

    def _status(self, q: Array) -> int:
        """0 when q lies in every joint range and every stroke in [0, stroke], else the reason's code."""
        for (lo, hi), value in zip(self.joint_ranges(), q, strict=True):
            if not lo - REACH_TOLERANCE <= value <= hi + REACH_TOLERANCE:
                return 2
        margins = self.stroke_margins(self.default_design, q[None])[0]
        strokes = np.concatenate([margins[0::3], margins[2::3]])
        return 3 if np.any(strokes < -REACH_TOLERANCE) else 0

    def ik_guess(self, first: Array) -> Array:
        """The IK of one point from a grid of starts over the joint ranges: in range if any start gets there."""
        target = np.asarray(first, dtype=float)
        grids = [np.linspace(lo, hi, GUESSES_PER_JOINT) for lo, hi in self.joint_ranges()]
        best: tuple[int, Array] | None = None
        for start in itertools.product(*grids):
            q = self._newton(target, np.array(start))
            if q is None:
                continue
            status = self._status(q)
            if status == 0:
                return q
            if best is None:
                best = (status, q)
        if best is None:
            return np.array([0.5 * (lo + hi) for lo, hi in self.joint_ranges()])
        return best[1]

    def reach(self, points: Array) -> PointReach:
        """IK of consecutive points (continuation; a fresh grid start after a failure), with a status each."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        joints = np.full((len(p), len(self.joint_names)), np.nan)
        status = np.zeros(len(p), dtype=int)
        previous: Array | None = None
        for i, target in enumerate(p):
            q = None if previous is None else self._newton(target, previous)
            if q is None:
                q = self._newton(target, self.ik_guess(target))
            if q is None:
                status[i], previous = 1, None
                continue
            joints[i], status[i], previous = q, self._status(q), q
        return PointReach(joints, status, REASONS)

    def inverse_kinematics(self, reference: tr.Reference, guess: Array) -> tr.JointTrajectory:
        """Newton IK of every joint on the tracked reference (continuation from ``guess``)."""
        q, dq, ddq = tracked_ik(
            self.kinematics, reference.position, reference.velocity, reference.acceleration, np.asarray(guess)
        )
        return tr.JointTrajectory(reference.time, q, dq, ddq)

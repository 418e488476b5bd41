"""What the study needs of a machine: one protocol, served by the crane and by any machine description.

The NLP of :mod:`hiab_sim.study.nlp` sees a machine only through :class:`StudyMachine`: its joints
q (n, in column order of joint samples), its actuators (one per joint, in the order of actuator
samples and of the EMLA set), its tracked coordinates r (n: the TCP's x and y in the plane, then
n - 2 more, each a joint or the TCP's attitude), its decision variables Xi (n_xi, in the order
of the design vector) and, per closed chain with a stroke that depends on its joint, the stroke
x(q_j, Xi) with its partials. Per sample the NLP's variables are q9 = (q, dq, ddq) (3 n).

Implementations: :class:`hiab_sim.study.machines.crane_model.CraneModel` (the XS 031's own
closed-form crane, bit for bit today's numbers) and
:class:`hiab_sim.study.machines.machine_model.MachineModel` (any machine file of
:mod:`hiab_sim.machine`). :func:`hiab_sim.study.machines.study_machine` picks one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.dynamics.interface import InverseDynamics
from hiab_sim.results.design_values import DesignValues

#: A design Xi (the crane's LinkLengths or a machine file's MachineDesign; ``as_array()`` gives its values).
Design = DesignValues


class Kinematics(Protocol):
    """The tracked coordinates of a machine (no dependence on Xi: the hinges are fixed)."""

    z: float

    def position(self, joints: Array) -> Array:
        """TCP (x, y, z) in the world for joint positions (T, n) [m]."""
        ...

    def samples(self, position: Array, velocity: Array, acceleration: Array) -> Any:
        """Tracked coordinates (T, n), rates and exact partials (T, n, 3 n)."""
        ...


@dataclass(frozen=True)
class PointReach:
    """Joints (R, n) of points, a status per point (0: reachable) and what each status means."""

    joints: Array
    status: np.ndarray
    reasons: tuple[str, ...]


class StudyMachine(Protocol):
    """A machine as the study sees it (module docstring); every length in m, angle in rad, force in N."""

    @property
    def name(self) -> str:
        """The machine's name."""
        ...

    @property
    def gravity(self) -> float:
        """Gravity [m/s^2], along -y."""
        ...

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The joints, in the column order of joint samples."""
        ...

    @property
    def joint_units(self) -> tuple[str, ...]:
        """``rad`` or ``m`` per joint."""
        ...

    @property
    def actuator_names(self) -> tuple[str, ...]:
        """The actuators, in the order of actuator samples and of the EMLA set."""
        ...

    @property
    def tracked_names(self) -> tuple[str, ...]:
        """The tracked coordinates, e.g. (x_tcp, y_tcp, xt2)."""
        ...

    @property
    def design_names(self) -> tuple[str, ...]:
        """The decision variables, in the order of Xi."""
        ...

    @property
    def stroke_chains(self) -> tuple[str, ...]:
        """The chains with stroke rows (their stroke depends on their joint)."""
        ...

    @property
    def stroke_joints(self) -> tuple[int, ...]:
        """Each stroke chain's joint index."""
        ...

    @property
    def kinematics(self) -> Kinematics:
        """The tracked kinematics."""
        ...

    @property
    def default_design(self) -> Design:
        """The design the file describes."""
        ...

    @property
    def hydraulic_cylinders(self) -> Any:
        """The cylinders the EMLAs replace in actuator order (iterable; ``supply_pressure``, friction), or None."""
        ...

    def design(self, values: ArrayLike) -> Design:
        """The design with these values (n_xi,)."""
        ...

    def design_bounds(self) -> tuple[Array, Array] | None:
        """Bounds of Xi declared by the machine itself, or None where the study gives them."""
        ...

    def joint_ranges(self) -> tuple[tuple[float, float], ...]:
        """The working range of every joint, (n,) pairs [rad or m]."""
        ...

    def joint_bounds(self, triangle_margin: float) -> tuple[Array, Array]:
        """Bounds (low, up) (n,) of the joint samples: the range, and a triangle chain's hinge-angle margin [rad]."""
        ...

    def with_stroke_ranges(self, ranges: Sequence[tuple[float, float]]) -> StudyMachine:
        """The machine with the stroke chains' joint ranges replaced (the inverse dynamics' input check)."""
        ...

    def buildable_ranges(self, stroke_margin: float) -> tuple[tuple[float, float], ...]:
        """Per stroke chain: its joint range over which the built design keeps ``stroke_margin`` [m] from both ends."""
        ...

    def inverse_dynamics(self, design: Design, path: str) -> InverseDynamics:
        """[f_x, v_x, a_x] = ID(q, dq, ddq, robot(Xi)) (seed eq. ``dynamics``) by ``mujoco`` or ``analytic``."""
        ...

    def design_partials(
        self, design: Design, joints: Any, path: str, fd_step: float, tcp_force: ArrayLike | None
    ) -> Array:
        """d(f, v, a)/dXi per sample by central differences, (K, 3 n, n_xi)."""
        ...

    def stroke_margins(self, design: Design, q: Array) -> Array:
        """Per stroke chain: x, Lc - x, stroke - x [m] at joint positions q (K, n), (K, 3 m)."""
        ...

    def stroke_margin_partials(self, design: Design, q: Array) -> tuple[Array, Array]:
        """Partials of :meth:`stroke_margins` w.r.t. q (K, 3 m, n) and Xi (K, 3 m, n_xi)."""
        ...

    def reach(self, points: Array) -> PointReach:
        """Joints of points of tracked coordinates (R, n) within the joint ranges and strokes, with a status."""
        ...

    def ik_guess(self, first: Array) -> Array:
        """Joints (n,) that start the Newton IK continuation at the first reference sample ``first`` (n,)."""
        ...

    def inverse_kinematics(self, reference: Any, guess: Array) -> Any:
        """Joint samples on the reference (Newton with continuation): a JointTrajectory."""
        ...

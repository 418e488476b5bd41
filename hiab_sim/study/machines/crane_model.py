"""The XS 031 crane description (:mod:`hiab_sim.crane`) as a :class:`~hiab_sim.study.machines.protocol.StudyMachine`.

Every quantity is the crane's own closed-form one (:mod:`hiab_sim.crane.mechanism`, the analytic and
MuJoCo inverse dynamics of :mod:`hiab_sim.dynamics`, the planar IK of
:mod:`hiab_sim.study.motion.workspace`), so a study of a crane file gives today's numbers bit for
bit. Its names are the crane's (:mod:`hiab_sim.crane.names`); its decision variables the seed's
Xi = [L, Lc0, Lc] per triangle chain, bounded by the study (``bounds:``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane import mechanism
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.names import ACTUATOR_NAMES, JOINT_NAMES
from hiab_sim.dynamics.interface import InverseDynamics, make_inverse_dynamics
from hiab_sim.hydraulics.cylinders import HydraulicSystem
from hiab_sim.study.machines.crane_reach import REASONS, planar_ik
from hiab_sim.study.machines.protocol import PointReach
from hiab_sim.study.motion import trajectory as tr


@dataclass(frozen=True)
class CraneModel:
    """A crane file as the study's machine (module docstring)."""

    crane: Crane
    kinematics: tr.TcpKinematics = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "kinematics", tr.TcpKinematics(self.crane))

    joint_names = JOINT_NAMES
    joint_units = ("rad", "rad", "m")
    actuator_names = ACTUATOR_NAMES
    tracked_names = ("x_tcp", "y_tcp", JOINT_NAMES[2])  # the TCP in the plane and the telescope's extension
    stroke_joints = (0, 1)

    @property
    def design_names(self) -> tuple[str, ...]:
        """Xi: the seed's [L, Lc0, Lc] of each triangle chain, ``<chain>.<L|Lc0|Lc>`` in chain order."""
        return tuple(f"{c.name}.{k}" for c in self.crane.chains for k in ("L", "Lc0", "Lc"))

    @property
    def stroke_chains(self) -> tuple[str, ...]:
        """The triangle chains (their strokes follow their joints 0 and 1)."""
        return tuple(c.name for c in self.crane.chains)

    @property
    def name(self) -> str:
        """The crane's name."""
        return self.crane.name

    @property
    def gravity(self) -> float:
        """[m/s^2]."""
        return self.crane.gravity

    @property
    def hydraulic_cylinders(self) -> HydraulicSystem | None:
        """The cylinders the EMLAs replace (the crane file's ``hydraulic_cylinders``), or None."""
        return self.crane.hydraulic_cylinders

    @property
    def default_design(self) -> LinkLengths:
        """The lengths the crane was built with."""
        return self.crane.default_lengths

    def design(self, values: ArrayLike) -> LinkLengths:
        """Xi = [lift L, Lc0, Lc, tilt L, Lc0, Lc] [m]."""
        return LinkLengths.from_array(np.asarray(values, dtype=float))

    def design_bounds(self) -> None:
        """A crane file declares no bounds: the study's ``bounds:`` give them."""
        return None

    def joint_ranges(self) -> tuple[tuple[float, float], ...]:
        """(theta1, theta2) ranges [rad] and the telescope's [m]."""
        return (self.crane.lift.joint_range, self.crane.tilt.joint_range, self.crane.telescope.joint_range)

    def joint_bounds(self, triangle_margin: float) -> tuple[Array, Array]:
        """const_h with const_k: the joint range and the hinge angle within [margin, pi - margin]."""
        low, up = np.zeros(3), np.zeros(3)
        for j, chain in enumerate(self.crane.chains):
            lo, hi = chain.joint_range
            low[j] = max(lo, chain.joint_offset - np.pi + triangle_margin)
            up[j] = min(hi, chain.joint_offset - triangle_margin)
        low[2], up[2] = self.crane.telescope.joint_range
        return low, up

    def with_stroke_ranges(self, ranges: Sequence[tuple[float, float]]) -> CraneModel:
        """The crane with the lift's and tilt's joint ranges replaced."""
        crane = self.crane
        return CraneModel(
            replace(
                crane,
                lift=replace(crane.lift, joint_range=ranges[0]),
                tilt=replace(crane.tilt, joint_range=ranges[1]),
            )
        )

    def buildable_ranges(self, stroke_margin: float) -> tuple[tuple[float, float], ...]:
        """The lift's and tilt's joint ranges of :func:`hiab_sim.crane.tolerance.buildable_crane`."""
        from hiab_sim.crane.tolerance import buildable_crane

        return tuple(c.joint_range for c in buildable_crane(self.crane, stroke_margin).chains)

    def inverse_dynamics(self, design: Any, path: str) -> InverseDynamics:
        """The crane's ``mujoco`` or ``analytic`` inverse dynamics at these lengths."""
        return make_inverse_dynamics(self.crane, design, path)

    def design_partials(
        self, design: Any, joints: Any, path: str, fd_step: float, tcp_force: ArrayLike | None
    ) -> Array:
        """d(f, v, a)/dXi (K, 9, 6) [per m] (the analytic path stacks the 12 designs in one call)."""
        from hiab_sim.study.nlp.id_partials import id_length_partials

        return id_length_partials(self.crane, design, joints, path, fd_step, tcp_force)

    def stroke_margins(self, design: Any, q: Array) -> Array:
        """x, Lc - x, stroke - x per chain [m] (seed eq. qus_a), (K, 6)."""
        cols = []
        for j, chain in enumerate(self.crane.chains):
            xi = getattr(design, chain.name)
            x = mechanism.joint_to_stroke(chain, xi, q[:, j])
            cols += [x, xi.Lc - x, chain.stroke - x]
        return np.column_stack(cols)

    def stroke_margin_partials(self, design: Any, q: Array) -> tuple[Array, Array]:
        """Exact partials of :meth:`stroke_margins` w.r.t. q (K, 6, 3) and Xi (K, 6, 6)."""
        K = q.shape[0]
        dq = np.zeros((K, 6, 3))
        dxi = np.zeros((K, 6, 6))
        for j, chain in enumerate(self.crane.chains):
            dx_dtheta, dx_dxi = mechanism.joint_to_stroke_partials(chain, getattr(design, chain.name), q[:, j])
            r = 3 * j
            dq[:, r, j], dq[:, r + 1, j], dq[:, r + 2, j] = dx_dtheta, -dx_dtheta, -dx_dtheta
            cols = slice(3 * j, 3 * j + 3)
            dxi[:, r, cols] = dx_dxi
            dxi[:, r + 1, cols] = -dx_dxi
            dxi[:, r + 1, 3 * j + 2] += 1.0  # d(Lc)/dLc
            dxi[:, r + 2, cols] = -dx_dxi
        return dq, dxi

    def reach(self, points: Array) -> PointReach:
        """Closed-form planar IK of (x, y, xt2) points within the joint ranges."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        ik = planar_ik(self.kinematics, self.crane, p[:, :2], p[:, 2])
        return PointReach(ik.joints, ik.status, REASONS)

    def ik_guess(self, first: Array) -> Array:
        """The closed-form IK of the first sample."""
        return np.asarray(self.reach(np.asarray(first)[None]).joints[0], dtype=float)

    def inverse_kinematics(self, reference: tr.Reference, guess: Array) -> tr.JointTrajectory:
        """Newton IK of (theta1, theta2) with the telescope prescribed, started at ``guess`` (n,)."""
        g = np.asarray(guess, dtype=float)
        return tr.inverse_kinematics(self.kinematics, reference, (float(g[0]), float(g[1])))

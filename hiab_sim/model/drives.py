"""What the EMLA drives add to the MJCF slides, and the pose a simulation model opens in.

The inverse-dynamics models (:mod:`hiab_sim.dynamics.mujoco_id`) are built *without* these
(``build_spec(crane, lengths)``): their rod force f_x is the load-side force of eq. ``torque_force``.
A simulation model (``build_spec(crane, lengths, drives=...)``) carries, per actuated slide,

* armature J_m (2 pi G / rho)^2 + M_sm [kg]: the rotor and screw inertia reflected to the rod
  (eq. ``torque_torque`` multiplied by k = 2 pi G / rho, with theta_m = k x);
* damping b_f [N s/m]: the screw's viscous friction (eq. ``torque_force``);
* a force range +-2 pi G (tau_peak - tau_f) / rho [N]: the peak-torque edge of the EMLA envelope
  (:func:`hiab_sim.emla.model.peak_force`);
* joint ranges at the physical stops: strokes [0, min(stroke, Lc)], telescope [0, stroke], and the
  boom hinges' range that those strokes allow (:func:`hiab_sim.crane.mechanism.reachable_joint_range`).

so the actuator force it receives is f_sm = f_x + (J_m k^2 + M_sm) a_x + b_f v_x, the screw side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.emla.config import EmlaSet
from hiab_sim.emla.model import peak_force
from hiab_sim.errors import InvalidInputError

Triple = tuple[float, float, float]


def _triple(field: str, values: object, unit: str, positive: bool = False) -> Triple:
    array = np.asarray(values, dtype=float)
    if array.shape != (3,) or not np.all(np.isfinite(array)) or np.any(array < 0) or (positive and np.any(array <= 0)):
        allowed = "three finite numbers " + ("> 0" if positive else ">= 0") + " (lift, tilt, telescope)"
        raise InvalidInputError(field, str(values), allowed, unit)
    return (float(array[0]), float(array[1]), float(array[2]))


@dataclass(frozen=True)
class SlideDrives:
    """Per actuated slide x1, x2, xt2 (lift, tilt, telescope): armature [kg], damping [N s/m], force limit [N]."""

    armature: Triple
    damping: Triple
    force_limit: Triple

    def __post_init__(self) -> None:
        object.__setattr__(self, "armature", _triple("drives.armature", self.armature, "kg"))
        object.__setattr__(self, "damping", _triple("drives.damping", self.damping, "N s/m"))
        object.__setattr__(self, "force_limit", _triple("drives.force_limit", self.force_limit, "N", positive=True))

    @classmethod
    def from_emla(cls, emlas: EmlaSet) -> SlideDrives:
        """The slides' armature, damping and force limit of an EMLA set (module docstring)."""
        params = emlas.as_tuple()
        return cls(
            armature=_as_triple(
                [p.motor.rotor_inertia * p.transmission_ratio**2 + p.screw_moving_mass for p in params]
            ),
            damping=_as_triple([p.viscous_friction for p in params]),
            force_limit=_as_triple([peak_force(p) for p in params]),
        )


def _as_triple(values: list[float]) -> Triple:
    return (values[0], values[1], values[2])


@dataclass(frozen=True)
class HomePose:
    """A loop-consistent pose the model opens in (qpos0, via joint ``ref``) and the forces that hold it.

    Attributes:
        qpos: Joint name -> value [rad or m] for every joint of the crane.
        force: Static slide forces (lift, tilt, telescope) that hold the pose against gravity [N].
        servo: Optional (stiffness [N/m], damping [N s/m]) per slide. With it the actuators are stroke
            servos, f = f_home + k_p (ctrl - (x - x_home)) - k_v v, so ``ctrl`` = 0 holds the home pose
            and a slider moves the stroke (the viewer file); without it they are force motors, ctrl = f [N].

    """

    qpos: dict[str, float]
    force: Triple
    servo: tuple[Triple, Triple] | None = None

    def __post_init__(self) -> None:
        for name, value in self.qpos.items():
            if not math.isfinite(value):
                raise InvalidInputError(f"home.qpos.{name}", value, "must be finite")
        force = np.asarray(self.force, dtype=float)
        if force.shape != (3,) or not np.all(np.isfinite(force)):
            raise InvalidInputError("home.force", str(self.force), "must be three finite numbers", "N")
        if self.servo is not None:
            _triple("home.servo.stiffness", self.servo[0], "N/m", positive=True)
            _triple("home.servo.damping", self.servo[1], "N s/m")


def servo_gains(armature: NDArray[np.float64], frequency_hz: float) -> tuple[Triple, Triple]:
    """Critically damped stroke servo on the reflected inertia m: k_p = m w^2, k_v = 2 m w, w = 2 pi f."""
    omega = 2.0 * math.pi * frequency_hz
    m = np.asarray(armature, dtype=float)
    return _as_triple(list(m * omega**2)), _as_triple(list(2.0 * m * omega))

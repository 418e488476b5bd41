"""Time samples exchanged by the inverse-dynamics paths (their one data type, no path imported here).

Conventions shared by both paths:
- Independent joints, in this order: ``theta1`` [rad], ``theta2`` [rad], ``xt2`` [m] (the
  source's Theta1, Theta2 and telescope extension, same zero and sign).
- Actuators, in this order: ``lift`` (stroke x1), ``tilt`` (x2), ``telescope`` (xt2); strokes
  in [m], 0 at the retracted pin-to-pin length x0.
- Force f_x [N] is positive when it pushes the actuator apart (extends it); velocity
  v_x = dx/dt [m/s]. f_x * v_x is the power the actuator delivers to the crane [W].
- An optional external force at the TCP, ``tcp_force`` [N], is the force the environment
  applies to the TCP (a payload of mass m hangs as (0, -m g, 0)), in the source world
  frame {W} (y up), shape (3,) or (T, 3).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.names import ACTUATOR_NAMES, JOINT_NAMES
from hiab_sim.errors import InvalidInputError

__all__ = ["ACTUATOR_NAMES", "JOINT_NAMES", "ActuatorSamples", "IdPath", "JointSamples"]

IdPath = Literal["mujoco", "analytic"]


@dataclass(frozen=True)
class JointSamples:
    """Samples of the independent joints: ``position``, ``velocity``, ``acceleration``, each (T, n joints)."""

    position: Array
    velocity: Array
    acceleration: Array

    def __post_init__(self) -> None:
        for name in ("position", "velocity", "acceleration"):
            value = np.asarray(getattr(self, name), dtype=float)
            if value.ndim != 2 or value.shape[1] < 1:
                raise InvalidInputError(f"joints.{name}", f"shape {value.shape}", "must have shape (T, n joints)")
            if not np.all(np.isfinite(value)):
                raise InvalidInputError(f"joints.{name}", "NaN or inf", "must be finite")
            object.__setattr__(self, name, value)
        if not (self.position.shape == self.velocity.shape == self.acceleration.shape):
            raise InvalidInputError("joints", "mismatched shapes", "position, velocity, acceleration must match")

    @classmethod
    def at_rest(cls, position: ArrayLike) -> JointSamples:
        """Static samples: the given positions (T, n joints) with zero velocity and acceleration."""
        p = np.atleast_2d(np.asarray(position, dtype=float))
        return cls(p, np.zeros_like(p), np.zeros_like(p))

    def __len__(self) -> int:
        return int(self.position.shape[0])


@dataclass(frozen=True)
class ActuatorSamples:
    """Actuator samples, each (T, n actuators) in the machine's actuator order.

    ``force`` f_x [N], ``velocity`` v_x [m/s], ``acceleration`` dv_x/dt [m/s^2] and
    ``stroke`` x [m].
    """

    force: Array
    velocity: Array
    acceleration: Array
    stroke: Array

    @property
    def power(self) -> Array:
        """Mechanical power delivered by each actuator, f_x v_x [W], (T, n actuators)."""
        return self.force * self.velocity

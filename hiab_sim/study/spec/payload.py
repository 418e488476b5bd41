"""A task's payload: a constant mass at the TCP, or one picked up at ``pick`` and released at ``release``.

The payload is a point mass m(t) carried rigidly at the TCP (no swing). Newton's law for it
gives the force it applies to the TCP, in {W} (y up, g along -y) [N]:

    F(t) = m(t) (g - a_tcp(t)),    g = (0, -g, 0),

its weight plus its inertia (d'Alembert force). With ``inertia`` false only the weight is kept
(quasi-static lifting, as the single-``payload`` studies of today). The schedule is a step in
time: m(t) = m for pick <= t < release, else 0 (at the pick instant the crane holds the load, at
the release instant it no longer does); without ``pick`` the load is held from the start, without
``release`` to the end. At each step the actuator forces jump by exactly -J_x^T dF, with J_x the
TCP's Jacobian with respect to the actuator strokes (virtual power, see
:mod:`hiab_sim.dynamics.mujoco_id`), and the power balance sum f v + F . v_tcp = dE/dt holds on
both sides of it.

a_tcp is the reference's TCP acceleration (the NLP tracks it within the acceleration band, so the
inertia force it leaves out is at most m times that band, e.g. 300 kg x 0.05 m/s^2 = 15 N
against a weight of 2943 N); a caller may pass the trajectory's own acceleration instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.yaml_fields import mapping, number


@dataclass(frozen=True)
class Payload:
    """Mass [kg] at the TCP, held for pick <= t < release [s] (None: from the start / to the end).

    Attributes:
        mass: Payload mass m >= 0 [kg].
        pick: Time it is picked up [s], or None (held from t = 0).
        release: Time it is released [s], or None (held to the end).
        inertia: Include the payload's inertia -m a_tcp, not only its weight.

    """

    mass: float
    pick: float | None = None
    release: float | None = None
    inertia: bool = True

    def __post_init__(self) -> None:
        if not (math.isfinite(self.mass) and self.mass >= 0.0):
            raise InvalidInputError("payload.mass", self.mass, "must be >= 0 and finite", "kg")
        for name in ("pick", "release"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value >= 0.0):
                raise InvalidInputError(f"payload.{name}", value, "must be >= 0 and finite", "s")
        if self.pick is not None and self.release is not None and not self.release > self.pick:
            raise InvalidInputError("payload.release", self.release, f"must be > pick = {self.pick:.6g}", "s")

    def mass_at(self, times: ArrayLike) -> Array:
        """m(t) [kg] at ``times`` (K,): the mass for pick <= t < release, else 0."""
        t = np.asarray(times, dtype=float)
        held = np.ones(t.shape, dtype=bool)
        if self.pick is not None:
            held &= t >= self.pick
        if self.release is not None:
            held &= t < self.release
        return np.where(held, self.mass, 0.0)

    def tcp_force(self, times: ArrayLike, tcp_acceleration: ArrayLike, gravity: float) -> Array:
        """F(t) = m(t) (g - a_tcp) in {W} [N], (K, 3), for the ID paths' ``tcp_force``.

        Args:
            times: Sample times (K,) [s].
            tcp_acceleration: TCP acceleration (K, 2) in the plane (x, y) or (K, 3) [m/s^2].
            gravity: g [m/s^2], along -y of {W}.

        """
        t = np.asarray(times, dtype=float).reshape(-1)
        a = np.asarray(tcp_acceleration, dtype=float)
        if a.ndim != 2 or a.shape[0] != len(t) or a.shape[1] not in (2, 3):
            raise InvalidInputError("tcp_acceleration", f"shape {a.shape}", f"must be ({len(t)}, 2) or ({len(t)}, 3)")
        accel = np.zeros((len(t), 3))
        if self.inertia:
            accel[:, : a.shape[1]] = a
        g = np.array([0.0, -gravity, 0.0])
        return self.mass_at(t)[:, None] * (g - accel)

    @classmethod
    def from_value(cls, value: Any, where: str = "payload") -> Payload:
        """A number (constant mass [kg]) or ``{mass, pick?, release?, inertia?}``."""
        if isinstance(value, int | float) and not isinstance(value, bool):
            return cls(number(value, where))
        d = mapping(value, where, {"mass", "pick", "release", "inertia"}, {"mass"})
        inertia = d.get("inertia", True)
        if not isinstance(inertia, bool):
            raise ConfigError(f"{where}.inertia: expected true or false, got {inertia!r}")
        pick, release = d.get("pick"), d.get("release")
        return cls(
            mass=number(d["mass"], f"{where}.mass"),
            pick=None if pick is None else number(pick, f"{where}.pick"),
            release=None if release is None else number(release, f"{where}.release"),
            inertia=inertia,
        )

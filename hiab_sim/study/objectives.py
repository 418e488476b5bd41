"""Objectives of the NLP, each a value and a gradient w.r.t. per-sample q9 and Xi (see :mod:`.nlp`).

* :class:`SquaredPowerCost` (``costf2``, the seed's eq. ``costf2``, the default):
  f = 1/2 Dt sum_k (sum_i P_i(t_k))^2 [W^2 s], a rectangle sum over every sample of the squared
  summed EMLA electrical power P_i (:mod:`hiab_sim.emla`, never f v / eta). It is a
  squared-power integral, not an energy.

An objective is chosen by name with :func:`make_objective`; a new one is a class with ``name``,
``unit``, ``value(state)`` and ``gradient(state, partials)`` plus one entry in :data:`OBJECTIVES`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from hiab_sim.emla import EmlaSet, electrical_power_partials
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.nlp import Array, Objective, SamplePartials, SampleState


class SquaredPowerCost:
    """f = 1/2 Dt sum_k (sum_i P_i(t_k))^2 (seed eq. ``costf2``) [W^2 s].

    Args:
        emlas: the EMLA set whose electrical power P_i the state carries.
        dt: the sample step Dt [s].

    """

    name = "costf2"
    unit = "W^2 s"

    def __init__(self, emlas: EmlaSet, dt: float) -> None:
        self.emlas = emlas
        self.dt = dt

    def value(self, state: SampleState) -> float:
        """1/2 Dt sum_k (sum_i P_i)^2 [W^2 s]."""
        total = state.power.sum(axis=1)
        return 0.5 * self.dt * float(np.sum(total**2))

    def gradient(self, state: SampleState, partials: SamplePartials) -> tuple[Array, Array]:
        """Dt (sum_i P_i) dP/d(f, v, a) chained through the inverse dynamics' partials."""
        act = state.actuators
        K = len(state.power)
        dP = np.zeros((K, 3, 9))  # power of actuator i w.r.t. Y = (f0 f1 f2 v0 v1 v2 a0 a1 a2)
        for i, p in enumerate(self.emlas):
            pf, pv, pa = electrical_power_partials(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
            dP[:, i, i], dP[:, i, 3 + i], dP[:, i, 6 + i] = pf, pv, pa
        total = state.power.sum(axis=1)
        dcost_dY = self.dt * total[:, None] * dP.sum(axis=1)  # (K, 9)
        return np.einsum("ky,kyq->kq", dcost_dY, partials.id_q), np.einsum("ky,kyx->x", dcost_dY, partials.id_xi)


#: Objectives by the name a study gives, each built from (EMLA set, sample step Dt [s]).
OBJECTIVES: dict[str, Callable[[EmlaSet, float], Objective]] = {"costf2": SquaredPowerCost}


def make_objective(name: str, emlas: EmlaSet, dt: float) -> Objective:
    """The objective called ``name`` (one of :data:`OBJECTIVES`)."""
    if name not in OBJECTIVES:
        raise InvalidInputError("objective", name, f"must be one of {', '.join(OBJECTIVES)}")
    return OBJECTIVES[name](emlas, dt)

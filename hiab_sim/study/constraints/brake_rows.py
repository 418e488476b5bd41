"""The holding brakes' rows: each brake must hold its cycle's first and last pose (``hold: brake``).

For every EMLA with a holding brake (:mod:`hiab_sim.emla.hold`), with the study's duty model:

    ``brake.<actuator> holding torque``: 1 - max(|tau_first|, |tau_last|) / M_4 >= 0 [-],

tau = f_x / k the static motor-shaft torque of the pose (k = 2 pi G / rho, eq. ``torque_force``). The
row depends on the first and last samples' forces only; its partial is -sign(tau) / (k M_4) at the
larger pose (a max of two: one-sided where they are equal), chained through the inverse dynamics.
"""

from __future__ import annotations

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaSet
from hiab_sim.study.nlp.interface import (
    ConstraintBlock,
    DenseRows,
    Relaxation,
    SamplePartials,
    SampleState,
)
from hiab_sim.study.spec.energy import DutySettings


class BrakeHolding(ConstraintBlock):
    """One row per EMLA with a holding brake: the brake holds the rest poses."""

    name = "brake"

    def __init__(self, emlas: EmlaSet) -> None:
        self.emlas = emlas.as_tuple()
        self.indices = [i for i, p in enumerate(self.emlas) if p.brake is not None]

    def row_names(self) -> list[str]:
        """``brake.<name> holding torque`` per EMLA with a brake."""
        return [f"{self.name}.{self.emlas[i].name} holding torque" for i in self.indices]

    def values(self, state: SampleState) -> Array:
        """1 - max |pose torque| / M_4 per EMLA with a brake."""
        assert state.duty is not None, "brake rows need the study's duty model"
        out = []
        for i in self.indices:
            hold = state.duty[i].hold
            assert hold is not None and hold.brake_margin is not None
            out.append(hold.brake_margin)
        return np.asarray(out, dtype=float)

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """D row / d f_x at the larger of the first and last samples, through the ID partials."""
        assert state.duty is not None
        K = len(state.joints.time)
        rows = np.zeros((len(self.indices), K, 3 * len(self.emlas)))  # w.r.t. Y = (f, v, a) of every actuator
        for r, i in enumerate(self.indices):
            p, hold = self.emlas[i], state.duty[i].hold
            assert hold is not None and p.brake is not None
            first, last = hold.first_pose_torque, hold.last_pose_torque
            k, tau = (0, first) if abs(first) > abs(last) else (K - 1, last)
            rows[r, k, i] = -np.sign(tau) / (p.transmission_ratio * p.brake.holding_torque)
        dq = np.einsum("mky,kyq->mkq", rows, partials.id_q)
        dxi = np.einsum("mky,kyx->mx", rows, partials.id_xi)
        return DenseRows(dq=dq, dxi=dxi)

    def relaxation(self, values: Array) -> Relaxation:
        """Per % of the holding torque M_4: the row 1 - |tau| / M_4 moves by (1 - g)(1 - 1 / 1.01)."""
        g = np.asarray(values, dtype=float)
        return Relaxation(("%",) * len(g), (1.0 - g) * (1.0 - 1.0 / 1.01))


def brake_blocks(emlas: EmlaSet, duty: DutySettings | None) -> list[ConstraintBlock]:
    """``[BrakeHolding]`` when the study's rest is held by the brakes, else ``[]``."""
    if duty is None or duty.hold_mode(emlas) != "brake":
        return []
    return [BrakeHolding(emlas)]

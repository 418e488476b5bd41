"""Motor thermal limits as NLP constraint rows: RMS torque and periodic winding temperature.

For every EMLA with thermal data (:class:`hiab_sim.emla.ThermalParams`), over the study's duty
(the cycle on the problem's grid followed by a rest at zero torque, :mod:`hiab_sim.emla.thermal`):

* ``thermal.<actuator> rms torque``: 1 - tau_rms / tau_cont >= 0 [-];
* ``thermal.<actuator> winding temperature``: (T_max - T_peak) / ``TEMPERATURE_SCALE`` >= 0.

Values and partials w.r.t. the actuator samples (f_x, v_x, a_x) come from
:func:`hiab_sim.emla.thermal_check` (smooth model, exact gradients); they are chained here through
the inverse dynamics' partials to q9 and Xi. Each row depends on every sample (an integral over
the cycle), so the Jacobian is :class:`~hiab_sim.study.nlp.interface.DenseRows`. The trapezoid rule on the
collocation grid is the optimiser's quadrature; the result re-checks on the 10x finer grid.
"""

from __future__ import annotations

import math

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaParams, EmlaSet, ThermalCheck, thermal_check
from hiab_sim.emla.duty_energy import DriveDuty
from hiab_sim.emla.thermal import Duty
from hiab_sim.study.nlp.interface import ConstraintBlock, DenseRows, Relaxation, SamplePartials, SampleState
from hiab_sim.study.spec.energy import DutySettings

#: Winding-temperature margins are divided by this [K] (O(1) rows).
TEMPERATURE_SCALE = 100.0
#: Peak temperature above T_max [K] reported when the winding has no fixed point (thermal runaway).
RUNAWAY_EXCESS = 1000.0


class ThermalLimits(ConstraintBlock):
    """RMS-torque and winding-temperature margins of the EMLAs with thermal data (two rows each)."""

    name = "thermal"

    def __init__(self, emlas: EmlaSet, duty: Duty) -> None:
        self.indices = [i for i, p in enumerate(emlas) if p.thermal is not None]
        self.emlas = emlas.as_tuple()
        self.duty = duty

    def row_names(self) -> list[str]:
        """Two rows per actuator: ``thermal.<name> rms torque``, ``thermal.<name> winding temperature``."""
        out = []
        for i in self.indices:
            out += [
                f"{self.name}.{self.emlas[i].name} rms torque",
                f"{self.name}.{self.emlas[i].name} winding temperature",
            ]
        return out

    def _checks(self, state: SampleState) -> list[tuple[int, ThermalCheck]]:
        act, t = state.actuators, state.joints.time
        if state.duty is not None:
            return [(i, duty_check(self.emlas[i], state.duty[i])) for i in self.indices]
        return [
            (
                i,
                thermal_check(self.emlas[i], t, act.force[:, i], act.velocity[:, i], act.acceleration[:, i], self.duty),
            )
            for i in self.indices
        ]

    def values(self, state: SampleState) -> Array:
        """[1 - tau_rms/tau_cont, (T_max - T_peak)/100 K] per actuator."""
        out = []
        for _, c in self._checks(state):
            out += [c.torque_margin, c.temperature_margin / TEMPERATURE_SCALE]
        return np.asarray(out, dtype=float)

    def jacobian(self, state: SampleState, partials: SamplePartials) -> DenseRows:
        """Rows' partials: d/d(f, v, a)_k from the thermal check, chained through the ID partials."""
        K, n = len(state.joints.time), len(self.emlas)
        rows = []
        for i, c in self._checks(state):
            for d, scale in ((c.d_rms, -1.0 / c.continuous_torque), (c.d_peak, -1.0 / TEMPERATURE_SCALE)):
                dY = np.zeros((K, 3 * n))  # w.r.t. Y = (f, v, a) of every actuator
                dY[:, i], dY[:, n + i], dY[:, 2 * n + i] = scale * d[0], scale * d[1], scale * d[2]
                rows.append(dY)
        dYs = np.stack(rows) if rows else np.zeros((0, K, 3 * n))
        dq = np.einsum("mky,kyq->mkq", dYs, partials.id_q)
        dxi = np.einsum("mky,kyx->mx", dYs, partials.id_xi)
        return DenseRows(dq=dq, dxi=dxi)

    def relaxation(self, values: Array) -> Relaxation:
        """Per % of the continuous torque (1 - tau_rms / tau_c moves by (1 - g)(1 - 1 / 1.01)), per K of T_max."""
        g = np.asarray(values, dtype=float)
        per_unit = np.empty(len(g))
        per_unit[0::2] = (1.0 - g[0::2]) * (1.0 - 1.0 / 1.01)
        per_unit[1::2] = 1.0 / TEMPERATURE_SCALE
        return Relaxation(("%", "K") * (len(g) // 2), per_unit)


def duty_check(params: EmlaParams, d: DriveDuty) -> ThermalCheck:
    """The thermal check of one EMLA from its duty model (hot windings and the rest's hold).

    Without a fixed point of the winding temperature (thermal runaway) the peak is reported as
    ``RUNAWAY_EXCESS`` above T_max with zero partials, so the row is infeasible but finite.
    """
    thermal = params.thermal
    assert thermal is not None
    peak = d.peak_temperature if math.isfinite(d.peak_temperature) else thermal.max_winding_temperature + RUNAWAY_EXCESS
    return ThermalCheck(
        rms_torque=d.rms_torque,
        continuous_torque=thermal.continuous_torque,
        peak_temperature=peak,
        max_temperature=thermal.max_winding_temperature,
        d_rms=d.rms_partials(),
        d_peak=d.peak_partials(),
    )


def thermal_blocks(emlas: EmlaSet, duty: DutySettings | None, cycle_time: float) -> list[ConstraintBlock]:
    """``[ThermalLimits]`` when the study has a duty and some EMLA has thermal data, else ``[]``.

    Args:
        emlas: The EMLA set.
        duty: The study's ``duty`` (None: no thermal rows).
        cycle_time: The cycle's duration T [s] (the study's grid duration).

    """
    if duty is None or not any(p.thermal is not None for p in emlas):
        return []
    return [ThermalLimits(emlas, duty.duty(cycle_time))]

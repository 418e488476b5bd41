"""Constraint rows whose partials are central differences: in each sample's inputs and in the design.

A :class:`DifferencedRows` block computes its rows g(design, q, dq, ddq) per sample (vectorised over
the samples, all perturbed together as the ID partials are) and differences them: in each of the
sample's 3 n inputs (positions, rates, accelerations; positions only when :attr:`uses_rates` is
false) with the step h = ``step`` max(1, |x|), and in each decision variable with the same rule. The
structural rows of both a crane file's and a machine file's study are built on it
(:mod:`hiab_sim.study.constraints.structure_rows`, :mod:`hiab_sim.study.constraints.machine_structure_rows`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.results.design_values import with_values
from hiab_sim.study.nlp.interface import PerSampleBlock, SamplePartials, SampleRows, SampleState


class DifferencedRows(PerSampleBlock):
    """Rows g(design, q, dq, ddq) per sample with central-difference partials in q9 and the design."""

    #: Relative central-difference step [-] (the study's ``solver.fd_step``).
    step: float
    #: Whether the rows depend on the rates and accelerations (else only their positions are differenced).
    uses_rates: bool = True

    def _rows(self, design: Any, position: Array, velocity: Array, acceleration: Array) -> Array:
        raise NotImplementedError

    def values(self, state: SampleState) -> Array:
        """The rows per sample, sample-major."""
        j = state.joints
        return self._rows(state.lengths, j.position, j.velocity, j.acceleration).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """Central differences in each of q9 (all samples at once; rates only if they enter) and the design."""
        j = state.joints
        q9 = np.concatenate([j.position, j.velocity, j.acceleration], axis=1)
        K, n, r = q9.shape[0], j.position.shape[1], len(self.sample_rows)
        dq = np.zeros((K, r, 3 * n))
        for k in range(3 * n if self.uses_rates else n):
            h = self.step * np.maximum(1.0, np.abs(q9[:, k]))
            up, down = q9.copy(), q9.copy()
            up[:, k] += h
            down[:, k] -= h
            rows_up = self._rows(state.lengths, up[:, :n], up[:, n : 2 * n], up[:, 2 * n :])
            rows_down = self._rows(state.lengths, down[:, :n], down[:, n : 2 * n], down[:, 2 * n :])
            dq[:, :, k] = (rows_up - rows_down) / (2.0 * h[:, None])
        values = state.lengths.as_array()
        dxi = np.zeros((K, r, len(values)))
        for k in range(len(values)):
            h = self.step * max(1.0, abs(values[k]))
            plus, minus = values.copy(), values.copy()
            plus[k] += h
            minus[k] -= h
            rows_up = self._rows(with_values(state.lengths, plus), j.position, j.velocity, j.acceleration)
            rows_down = self._rows(with_values(state.lengths, minus), j.position, j.velocity, j.acceleration)
            dxi[:, :, k] = (rows_up - rows_down) / (2.0 * h)
        return SampleRows(dq, dxi)

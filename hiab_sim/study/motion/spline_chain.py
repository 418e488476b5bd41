"""The chain rule from per-sample partials to B-spline coefficients, on each sample's band of the basis.

A joint trajectory q_j(t) = sum_n c_jn B_n(t) and its rates are the spline matrices B (3 orders, K
samples, N coefficients) times the coefficients. A row that depends on one sample k only has
d(row)/dc_jn = sum_o d(row)/dq9[o, j] B[o, k, n], and B[:, k, n] is zero outside the W = degree + 1
basis functions that are nonzero at t_k. :class:`SplineChain` multiplies by B on that band alone (the
same products, in the same order, as with the full matrices) and scatters them into the rows of a
Jacobian whose columns are [n_xi design variables, then N coefficients per joint].
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array


def spline_band(B: Array) -> tuple[NDArray[np.intp], Array]:
    """The band of spline matrices B (3, K, N): window starts s_k (K,) and B on the windows (3, K, W).

    Per sample k the W columns from s_k on hold every nonzero of B[:, k] (W: the widest support,
    degree + 1 for a B-spline).
    """
    nonzero = np.any(B != 0.0, axis=0)  # (K, N)
    first = np.argmax(nonzero, axis=1)
    last = B.shape[2] - 1 - np.argmax(nonzero[:, ::-1], axis=1)
    width = int(np.max(last - first)) + 1
    start = np.minimum(first, B.shape[2] - width).astype(np.intp)
    columns = start[:, None] + np.arange(width)
    return start, np.take_along_axis(B, np.broadcast_to(columns, (3, *columns.shape)), axis=2)


class SplineChain:
    """Per-sample rows' partials w.r.t. q9 through the spline matrices B (3, K, N) into Jacobian rows.

    Args:
        B: The spline matrices (value, rate, acceleration) at the K samples, (3, K, N).
        n_xi: Design-variable columns before the coefficients.
        n_joints: Joints; coefficient column of joint j, coefficient n: n_xi + j N + n.

    """

    def __init__(self, B: Array, n_xi: int, n_joints: int) -> None:
        self.B = B
        self.n_xi, self.n_joints = n_xi, n_joints
        #: the band of B: the W basis functions from ``band_start[k]`` on hold every nonzero at sample k
        self.band_start, self.band = spline_band(B)
        self.width = n_xi + n_joints * B.shape[2]
        self._indices: dict[int, NDArray[np.intp]] = {}

    def write_sample_rows(self, dq: Array, out: Array, scale: float) -> None:
        """Write ``scale`` d(rows)/dc into the coefficient columns of ``out`` (K r, n_xi + n N).

        ``dq``: (K, r, 3 n) partials of r rows per sample w.r.t. that sample's q9 (index o n + j for
        order o, joint j); row k r + m of ``out`` is row m of sample k. ``out`` must be contiguous.
        """
        K, r = dq.shape[0], dq.shape[1]
        band = np.einsum("kmoj,okb->kbmj", dq.reshape(K, r, 3, self.n_joints), self.band) * scale
        flat = out.reshape(-1)
        if not np.may_share_memory(flat, out):
            raise AssertionError("a block's Jacobian rows must be contiguous")
        flat[self._index(r)] = band.reshape(-1)

    def _index(self, r: int) -> NDArray[np.intp]:
        """Flat indices into (K r, width) rows of the band entries, in (k, b, m, j) order (cached per r).

        Row k r + m, column n_xi + j N + s_k + b: the coefficient b of the band of sample k for joint j.
        """
        if r not in self._indices:
            K, W, N = self.B.shape[1], self.band.shape[2], self.B.shape[2]
            k, b, m, j = np.ix_(np.arange(K), np.arange(W), np.arange(r), np.arange(self.n_joints))
            column = self.n_xi + j * N + self.band_start[k] + b
            self._indices[r] = ((k * r + m) * self.width + column).reshape(-1).astype(np.intp)
        return self._indices[r]

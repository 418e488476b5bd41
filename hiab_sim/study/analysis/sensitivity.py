"""KKT multipliers of the active constraints at an optimum, in physical units.

scipy's SLSQP does not return multipliers, so they are recovered at the optimum z* from the KKT
stationarity condition with the problem's exact gradients,

    grad f(z*) = sum_{i in A} lambda_i grad g_i(z*) + E^T mu + sum_{bounds} nu_k (+-e_k),   lambda, nu >= 0,

by non-negative least squares on the active set A (rows with scaled margin <= ``active_tolerance``,
Xi on a bound), the equality multipliers mu split into mu+ - mu-. lambda_i is the decrease of
the scaled cost f / f_scale per unit relaxation of the scaled row g_i >= 0 -> g_i >= -delta, so
the cost change of relaxing a physical limit by one unit u is lambda_i f_scale dg_i/du:

* a bound of Xi [m]: dg/du = 1e-3 / XI_SCALE per ``mm``;
* an EMLA limit g = 1 - (y / y_max)^2 (peak torque, rated speed, voltage; rows scaled by 1 / (1 - m)):
  raising y_max by 1 % changes g by (1 - g)(1 - 1 / 1.01^2), per ``%`` (summed over the samples
  where the limit is active);
* a tracking band b: the row 1 - e / (b phi) at an active sample (e = b phi) changes by 1 / b per
  unit of b, so 1e-3 / b per ``mm`` (or mm/s, mm/s^2);
* the stroke and working-range rows (scale 0.1 m) and the mounting rows (scale 0.1 m):
  1e-3 / 0.1 per ``mm``;
* a joint-velocity limit: the row 1 - dtheta / limit changes by ~0.01 per ``%``.

Rows with the same limit at different samples (``... at t=...``) are summed into one entry.
"""

from __future__ import annotations

import re

import numpy as np
from scipy.optimize import nnls

from hiab_sim.results.analysis_sections import Multiplier, Sensitivity
from hiab_sim.study.nlp import blocks as bl
from hiab_sim.study.nlp.mounting_rows import MOUNTING_SCALE
from hiab_sim.study.nlp.problem import XI_SCALE, LinkLengthProblem

Array = np.ndarray
#: Scaled margin below which a row counts as active.
ACTIVE_TOLERANCE = 1e-6
_SAMPLE = re.compile(r" at t=[-0-9.e+]+ s$")
XI_NAMES = ("lift.L", "lift.Lc0", "lift.Lc", "tilt.L", "tilt.Lc0", "tilt.Lc")


def kkt_multipliers(
    problem: LinkLengthProblem, z: Array, active_tolerance: float = ACTIVE_TOLERANCE
) -> tuple[Array, Array, Array, float]:
    """(lambda per row (m,), nu_low (6,), nu_up (6,), relative residual) by NNLS on the active set."""
    z = np.asarray(z, dtype=float)
    grad = problem.cost_gradient(z)
    jac = problem.constraints_jacobian(z)
    g = problem.constraints(z)
    eq = problem.equalities_jacobian(z)
    active = np.flatnonzero(g <= active_tolerance)
    n_xi = problem.n_xi
    zx = z[:n_xi]
    at_low = np.flatnonzero(zx - problem.lower[:n_xi] <= 1e-9)
    at_up = np.flatnonzero(problem.upper[:n_xi] - zx <= 1e-9)
    eye = np.eye(problem.n)
    columns = [jac[active].T, eq.T, -eq.T, eye[:, at_low], -eye[:, at_up]]
    A = np.hstack(columns)
    x, residual = nnls(A, grad, maxiter=50 * A.shape[1])
    k = len(active)
    lam = np.zeros(len(g))
    lam[active] = x[:k]
    start = k + 2 * eq.shape[0]
    nu_low, nu_up = np.zeros(n_xi), np.zeros(n_xi)
    nu_low[at_low] = x[start : start + len(at_low)]
    nu_up[at_up] = x[start + len(at_low) :]
    return lam, nu_low, nu_up, float(residual / max(np.linalg.norm(grad), 1e-300))


def _row_unit(problem: LinkLengthProblem, block: str, row: str, value: float) -> tuple[str, float]:
    """(unit, d(scaled row)/d(one unit of relaxation)) of a row of a block."""
    study = problem.study
    if block == "envelope":
        m = problem.envelope_margin
        g = value * (1.0 - m) + m
        return "%", (1.0 - g) * (1.0 - 1.0 / 1.01**2) / (1.0 - m)
    if block.startswith("tracking."):
        order = block.split(".")[1]
        band = getattr(study.tracking, order)
        unit = {"position": "mm", "velocity": "mm/s", "acceleration": "mm/s^2"}[order]
        return unit, 1e-3 / band
    if block in ("stroke", "working_range", "buildable_range"):
        return "mm", 1e-3 / bl.STROKE_SCALE
    if block == "mounting":
        return "mm", 1e-3 / MOUNTING_SCALE
    if block == "joint_velocity":
        return "%", 0.01
    return "scaled unit", 1.0


def sensitivity(problem: LinkLengthProblem, z: Array, active_tolerance: float = ACTIVE_TOLERANCE) -> Sensitivity:
    """The ``sensitivity`` section: every active constraint's multiplier in physical units (module docstring)."""
    lam, nu_low, nu_up, residual = kkt_multipliers(problem, z, active_tolerance)
    cost = problem.evaluate(z).cost
    scale = problem.cost_scale
    g = problem.constraints(z)
    entries: dict[str, list[float]] = {}  # key -> [lambda sum, cost per unit, rows]
    units: dict[str, str] = {}
    for block, rows in problem.layout.slices.items():
        for i in range(rows.start, rows.stop):
            if lam[i] <= 0.0:
                continue
            name = problem.constraint_names[i]
            key = _SAMPLE.sub("", name)
            if block == "envelope" or block.startswith("tracking.") or block == "joint_velocity":
                key = key.rsplit(" ", 2)[0] if block.startswith("tracking.") else key
            unit, per_unit = _row_unit(problem, block, name, float(g[i]))
            entry = entries.setdefault(key, [0.0, 0.0, 0.0])
            entry[0] += lam[i]
            entry[1] += lam[i] * per_unit * scale
            entry[2] += 1
            units[key] = unit
    for k, name in enumerate(XI_NAMES):
        for side, nu in (("low", nu_low[k]), ("up", nu_up[k])):
            if nu > 0.0:
                key = f"bound {name} {side} = {(problem.lower if side == 'low' else problem.upper)[k] * XI_SCALE:g} m"
                entries[key] = [float(nu), float(nu) * 1e-3 / XI_SCALE * scale, 1]
                units[key] = "mm"
    multipliers = tuple(
        Multiplier(
            constraint=key,
            multiplier=float(v[0]),
            unit=units[key],
            cost_per_unit_W2s=float(v[1]),
            percent_per_unit=float(100.0 * v[1] / cost),
            rows=int(v[2]),
        )
        for key, v in sorted(entries.items(), key=lambda kv: -kv[1][1])
    )
    return Sensitivity(cost_W2s=cost, active_tolerance=active_tolerance, kkt_residual=residual, multipliers=multipliers)

"""KKT multipliers of the active constraints at an optimum, in physical units.

scipy's SLSQP does not return multipliers, so they are recovered at the optimum z* from the KKT
stationarity condition with the problem's exact gradients,

    grad f(z*) = sum_{i in A} lambda_i grad g_i(z*) + E^T mu + sum_{bounds} nu_k (+-e_k),   lambda, nu >= 0,

by non-negative least squares on the active set A (rows with scaled margin <= ``active_tolerance``,
Xi on a bound), the equality multipliers mu split into mu+ - mu-. lambda_i is the decrease of
the scaled cost f / f_scale per unit relaxation of the scaled row g_i >= 0 -> g_i >= -delta, so
the objective's change on relaxing a physical limit by one unit u is lambda_i f_scale dg_i/du:

* a bound of Xi [m]: dg/du = 1e-3 / XI_SCALE per ``mm``;
* an EMLA limit g = 1 - (y / y_max)^2 (peak torque, rated speed, voltage; rows scaled by 1 / (1 - m)):
  raising y_max by 1 % changes g by (1 - g)(1 - 1 / 1.01^2), per ``%`` (summed over the samples
  where the limit is active);
* a tracking band b: the row 1 - e / (b phi) at an active sample (e = b phi) changes by 1 / b per
  unit of b, so 1e-3 / b per ``mm`` (or mm/s, mm/s^2);
* the stroke and working-range rows (scale 0.1 m) and the mounting rows (scale 0.1 m):
  1e-3 / 0.1 per ``mm``;
* a joint-velocity limit: the row 1 - dtheta / limit changes by ~0.01 per ``%``;
* any other block: its own :meth:`~hiab_sim.study.nlp.interface.ConstraintBlock.relaxation`
  (every block states its rows' unit; thermal rows per ``%`` of the continuous torque and per ``K``
  of the winding limit, joint limits per ``mrad`` or ``mm``, an epsilon row per unit of its objective).

Rows of one limit (:meth:`~hiab_sim.study.nlp.interface.ConstraintBlock.limit_name`: the same limit at
different samples, ``... at t=...``) are summed into one entry. The decrease is in the objective's
own unit (W^2 s for ``costf2``, J for ``battery_energy``) and in % of its value at the optimum;
for several tasks the objective is the weighted sum and the rows are named ``<task>: <row>``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from hiab_sim.arrays import Array
from hiab_sim.results.analysis_sections import Multiplier, Sensitivity
from hiab_sim.study.nlp.interface import bound_row_name
from hiab_sim.study.nlp.problem import StudyProblem
from hiab_sim.study.nlp.task_problem import XI_SCALE

#: Scaled margin below which a row counts as active.
ACTIVE_TOLERANCE = 1e-6


def kkt_multipliers(
    problem: StudyProblem, z: Array, active_tolerance: float = ACTIVE_TOLERANCE
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


def sensitivity(problem: StudyProblem, z: Array, active_tolerance: float = ACTIVE_TOLERANCE) -> Sensitivity:
    """The ``sensitivity`` section: every active constraint's multiplier in physical units (module docstring).

    Each block gives its rows' units (:meth:`~hiab_sim.study.nlp.interface.ConstraintBlock.relaxation`)
    and groups its rows into limits (:meth:`~hiab_sim.study.nlp.interface.ConstraintBlock.limit_name`); the
    objective's decrease is in the objective's own unit and in % of its value at z.
    """
    lam, nu_low, nu_up, residual = kkt_multipliers(problem, z, active_tolerance)
    value = problem.evaluate(z).cost
    scale = problem.cost_scale
    g = problem.constraints(z)
    entries: dict[str, list[float]] = {}  # key -> [lambda sum, objective decrease per unit, rows]
    units: dict[str, str] = {}
    for stacked in problem.blocks:
        block, rows = stacked.block, stacked.rows
        relax = block.relaxation(g[rows])
        local_names = problem.problems[stacked.task].constraint_names[stacked.local]
        for i, (row, unit, per_unit) in enumerate(zip(local_names, relax.units, relax.per_unit, strict=True)):
            lam_i = lam[rows.start + i]
            if lam_i <= 0.0:
                continue
            key = problem.row_name(stacked.task, block.limit_name(row))
            entry = entries.setdefault(key, [0.0, 0.0, 0.0])
            entry[0] += lam_i
            entry[1] += lam_i * per_unit * scale
            entry[2] += 1
            units[key] = unit
    for k, name in enumerate(problem.model.design_names):
        for side, nu in (("low", nu_low[k]), ("up", nu_up[k])):
            if nu > 0.0:
                key = bound_row_name(name, side, (problem.lower if side == "low" else problem.upper)[k] * XI_SCALE)
                entries[key] = [float(nu), float(nu) * 1e-3 / XI_SCALE * scale, 1]
                units[key] = "mm"
    multipliers = tuple(
        Multiplier(
            constraint=key,
            multiplier=float(v[0]),
            unit=units[key],
            objective_decrease_per_unit=float(v[1]),
            percent_per_unit=float(100.0 * v[1] / value),
            rows=int(v[2]),
        )
        for key, v in sorted(entries.items(), key=lambda kv: -kv[1][1])
    )
    return Sensitivity(
        objective=problem.objective.name,
        objective_unit=problem.objective.unit,
        objective_value=value,
        active_tolerance=active_tolerance,
        kkt_residual=residual,
        multipliers=multipliers,
    )

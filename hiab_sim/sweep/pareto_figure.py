"""The Pareto front's figure: objective against criterion, both as changes from the plain optimum [%].

Reads the front of :func:`hiab_sim.sweep.pareto.pareto_front` (its points and least-criterion design);
computes nothing of its own but the percentages it draws.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.percent import change_percent
from hiab_sim.style import colour
from hiab_sim.sweep.pareto import CRITERIA, CRITERION_AXIS, FrontPoint


def front_figure_png(
    front: list[FrontPoint], name: str, title: str, objective: str = "objective", least_design: FrontPoint | None = None
) -> bytes:
    """PNG of the front: the objective's and the criterion's change from the plain optimum [%], one point each.

    ``least_design`` (:class:`Front` ``least``): the design minimising the criterion alone, drawn apart
    (a hollow diamond, not joined to the front) where given.

    Both axes are the change from the plain optimum (the first point) in %, so a front over a few
    tenths of a percent reads as what it is; the top axis gives the criterion in its unit, the title
    the spans. Points that did not converge have no value on the front: a dotted vertical line marks
    their limit epsilon. ``title`` names the study, ``objective`` its objective
    (registry name, :data:`OBJECTIVE_AXIS`).
    """
    from hiab_sim.figure_io import new_figure, png_bytes
    from hiab_sim.sweep.map_output import OBJECTIVE_AXIS

    words = CRITERION_AXIS.get(name, name.replace("_", " "))
    what = OBJECTIVE_AXIS.get(objective, objective.replace("_", " "))
    unit = CRITERIA[name]
    k = 1e-3 if unit == "N" else 1.0  # forces in kN
    unit = "kN" if unit == "N" else unit
    base, base_objective = front[0].criterion, front[0].objective
    ok = [p for p in front if p.accepted]

    def change(value: ArrayLike, of: float) -> Array:
        return change_percent(of, np.asarray(value, dtype=float))

    fig = new_figure((6.6, 4.8))
    ax = fig.add_subplot()
    ax.plot(change([p.criterion for p in ok], base), change([p.objective for p in ok], base_objective), "o-",
            color=colour("optimal"), label=f"least {what} for each limit on the {words}")  # fmt: skip
    ax.plot(0.0, 0.0, "*", color=colour("initial"), mec="k", ms=14, label=f"plain optimum (no limit on the {words})")
    if least_design is not None:
        alone = f"least {words} the limits allow ({words} minimised alone)"
        ax.plot(change(least_design.criterion, base), change(least_design.objective, base_objective), "D",
                mfc="none", mec="k", ms=7, label=alone)  # fmt: skip
    bad = [p for p in front if not p.accepted]
    for i, p in enumerate(bad):  # a limit, not a value: a vertical line at its epsilon
        label = f"did not converge ({len(bad)}): no point at this limit" if i == 0 else None
        ax.axvline(float(change(p.epsilon, base)), color="red", ls=":", lw=1.5, label=label)
    if base != 0.0:

        def to_value(d: ArrayLike) -> ArrayLike:
            return k * (base + abs(base) * np.asarray(d, dtype=float) / 100.0)

        def from_value(c: ArrayLike) -> ArrayLike:
            return change_percent(k * base, np.asarray(c, dtype=float))

        ax.secondary_xaxis("top", functions=(to_value, from_value)).set_xlabel(f"{words} [{unit}]")
    ax.set_xlabel(f"{words}: change from the plain optimum [%]")
    ax.set_ylabel(f"{what}: change from the plain optimum [%]")
    least = min(ok, key=lambda p: p.criterion)
    extra = [] if least_design is None else [least_design.criterion]
    xs = np.concatenate(
        [change([p.criterion for p in ok] + extra, base), change([p.epsilon for p in bad], base), [0.0]]
    )
    span = max(float(np.ptp(xs)), 1e-9)
    ax.set_xlim(xs.min() - 0.05 * span, xs.max() + 0.05 * span)  # the limits that failed included
    ax.set_title(
        f"{title}: what limiting the {words} costs\nthe front: {words} {change(least.criterion, base):+.2f} % "
        f"({k * base:.2f} to {k * least.criterion:.2f} {unit}) for {change(least.objective, base_objective):+.2f} % "
        f"{what}",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    return png_bytes(fig)

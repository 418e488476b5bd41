"""Generated blocks of the design-space page: the default study's energy map, the two shipped sweeps, the Pareto front.

Each block is a function of :class:`~hiab_sim.docs_site.results_data.RunData` returning Markdown from
the committed ``energy_map.json``, ``sweep.parquet`` and ``pareto.json`` fields of those commands'
output folders (recorded under the folder's name).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from hiab_sim.docs_site.markdown import table
from hiab_sim.docs_site.results_data import RunData
from hiab_sim.docs_site.results_format import kilo
from hiab_sim.percent import change_percent, saving_percent

#: The output folders' names (and so their data files') that ``scripts/results_pages.sh`` writes.
ENERGY_MAP, PARETO = "xs031_spiral_energy_map", "xs031_spiral_pareto_peak_force"
MOUNTING_SWEEP, PAYLOAD_GEAR_SWEEP = "xs031_mounting_space", "xs031_payload_gear"


def energy_map(runs: RunData) -> str:
    """How many cells are feasible, the best one against the base design, what binds elsewhere."""
    m = runs.section(ENERGY_MAP, "energy_map")
    best, base = m("best_feasible_cell"), m("at_base")
    names = m("variables")
    xi = dict(zip(("lift.L", "lift.Lc0", "lift.Lc", "tilt.L", "tilt.Lc0", "tilt.Lc"), best["xi_m"], strict=True))
    binding = sorted(m("infeasible_cells_by_binding_constraint").items(), key=lambda kv: -kv[1])
    where = ", ".join(f"`{name}` {count}" for name, count in binding)
    return (
        f"Map of `xs031_spiral` over {' x '.join(names)} at the {m('base')}: {m('feasible_cells')} of "
        f"{m('cells')} cells are feasible; the best feasible cell ({', '.join(f'{n} = {xi[n]:.3f} m' for n in names)}) "
        f"has the objective {change_percent(base['objective'], best['objective']):+.2f} % from the base design's and "
        f"the battery energy {kilo(base['battery_energy_J'])} → {kilo(best['battery_energy_J'])} kJ. Infeasible "
        f"cells by their binding constraint: {where}."
    )


def _rows(runs: RunData, sweep: str) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = runs.section(sweep, "sweep")("rows")
    return rows


def _battery_saved(r: dict[str, Any]) -> str:
    """The battery energy the optimisation saves at a finished point, (start - optimum) / |start| [%]."""
    return f"{saving_percent(r['start_battery_energy_J'], r['opt_battery_energy_J']):.2f} %"


def mounting_sweep(runs: RunData) -> str:
    """Battery energy saved and the optimum's base distances against the mounting space opened."""
    rows = _rows(runs, MOUNTING_SWEEP)
    cells = []
    for r in rows:
        ok = r["status"] == "ok"
        cells.append(
            (
                f"{r['parameters']['opening_percent']:g} %",
                _battery_saved(r) if ok else r["status"],
                f"{r['opt_lift_L_m']:.3f} / {r['opt_tilt_L_m']:.3f}" if ok else "",
                f"{r['opt_lift_Lc_m']:.3f} / {r['opt_tilt_Lc_m']:.3f}" if ok else "",
            )
        )
    return table(
        ("opening p", "battery energy saved", "optimal L lift / tilt [m]", "optimal Lc lift / tilt [m]"), cells
    )


def payload_gear_sweep(runs: RunData) -> str:
    """Battery energy at the start and the saving per payload and lift gear ratio; failed points with their reason."""
    rows = _rows(runs, PAYLOAD_GEAR_SWEEP)
    cells = []
    for r in rows:
        p = r["parameters"]
        if r["status"] == "ok":
            outcome = (
                f"{kilo(r['start_battery_energy_J'])} → {kilo(r['opt_battery_energy_J'])} kJ",
                _battery_saved(r),
            )
        else:
            outcome = (f"{r['status']}: {r['message']}", "")
        cells.append((f"{p['payload']:g} kg", f"{p['emla.lift.gear_ratio']:g}", *outcome))
    return table(("payload", "lift G", "battery energy, start → optimum", "battery energy saved"), cells)


def pareto(runs: RunData) -> str:
    """The front: criterion and objective of every point relative to the energy optimum's."""
    f = runs.section(PARETO, "pareto")
    points = f("points")
    first = points[0]
    rows: list[tuple[object, ...]] = [
        (
            i,
            f"{p['criterion']:.5g} {f('unit')}",
            f"{change_percent(first['criterion'], p['criterion']):+.2f} %",
            f"{change_percent(first['objective'], p['objective']):+.2f} %",
            "yes" if p["accepted"] else "no (not converged)",
        )
        for i, p in enumerate(points)
    ]
    least = f("least_criterion")
    rows.append(
        (
            "least",
            f"{least['criterion']:.5g} {f('unit')}",
            f"{change_percent(first['criterion'], least['criterion']):+.2f} %",
            f"{change_percent(first['objective'], least['objective']):+.2f} %",
            "the least-criterion design (criterion minimised alone; not on the front)",
        )
    )
    header = ("point", f"{f('criterion')}", "criterion vs optimum", "objective vs optimum", "converged")
    return table(header, rows)


BLOCKS: dict[str, Callable[[RunData], str]] = {
    "design-space-energy-map": energy_map,
    "design-space-mounting-sweep": mounting_sweep,
    "design-space-payload-gear-sweep": payload_gear_sweep,
    "design-space-pareto": pareto,
}

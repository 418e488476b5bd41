"""Reports of the cross-validation (``hiab-sim validate``): JSON, the markdown table of docs/validation.md, force plots.

Every file is written atomically (:mod:`hiab_sim.atomic_io`); the computations are in
:mod:`hiab_sim.validation`.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path
from typing import Any

from hiab_sim.atomic_io import write_atomic
from hiab_sim.crane.description import Crane
from hiab_sim.dynamics.samples import ACTUATOR_NAMES
from hiab_sim.figure_io import new_figure, save_png
from hiab_sim.validation import CaseResult, Tolerances


def markdown_table(results: list[CaseResult], tolerances: Tolerances) -> str:
    """The validation table (markdown), as inserted in docs/validation.md."""
    lines = [
        "| case | samples | length sets | max abs force error [N] | max rel force error | "
        "max abs velocity error [m/s] | 6D form: max rel force error | balance (analytic) | balance (MuJoCo) | pass |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|:---:|",
    ]
    for r in results:
        lines.append(
            f"| {r.name} | {r.samples} | {r.length_sets} | {max(r.force_abs_error):.2e} | "
            f"{max(r.force_rel_error):.2e} | {max(r.velocity_abs_error):.2e} | {max(r.spatial_force_rel_error):.2e} | "
            f"{r.balance_analytic:.2e} ({r.balance_kind}) | {r.balance_mujoco:.2e} | {'yes' if r.passed else 'NO'} |"
        )
    lines.append("")
    lines.append(
        'Errors are MuJoCo minus analytic (the planar se(2) form that `path="analytic"` runs); the 6D column '
        "is the 6D screw-theory form against MuJoCo. Balance: max |sum f v + F_tcp . v_tcp - dE/dt| over the peak "
        "power (power), or max |f - d(U - F_tcp . p_tcp)/dx| over the peak force (virtual work, static cases). "
        f"Tolerances: force errors <= {tolerances.force_relative:g} of each actuator's peak |f| over the case, "
        f"velocity error <= {tolerances.velocity_absolute:g} m/s, analytic balance <= {tolerances.balance_relative:g}."
    )
    return "\n".join(lines) + "\n"


def report_dict(crane: Crane, results: list[CaseResult], tolerances: Tolerances) -> dict[str, Any]:
    """JSON-ready report."""
    cases = []
    for r in results:
        entry = asdict(r)
        entry.pop("traces")
        entry["actuators"] = list(ACTUATOR_NAMES)
        cases.append(entry)
    return {
        "crane": crane.name,
        "tolerances": asdict(tolerances),
        "passed": all(r.passed for r in results),
        "cases": cases,
    }


def plot_case(result: CaseResult) -> Any:
    """Figure: both force traces (top) and their difference (bottom) for each actuator."""
    traces = result.traces
    fig = new_figure((12, 6))
    axes = fig.subplots(2, 3, sharex=True)
    style = {"linestyle": "-"} if traces["time"] else {"linestyle": "none", "marker": "."}
    for j, name in enumerate(ACTUATOR_NAMES):
        top, bottom = axes[0, j], axes[1, j]
        top.plot(traces["axis"], traces["analytic"][:, j] / 1e3, label="analytic", color="C0", **style)
        top.plot(traces["axis"], traces["mujoco"][:, j] / 1e3, label="MuJoCo", color="C1", linestyle="--")
        top.set_title(f"{name}")
        top.set_ylabel("f_x [kN]")
        bottom.plot(traces["axis"], traces["mujoco"][:, j] - traces["analytic"][:, j], color="C3", **style)
        bottom.set_ylabel("MuJoCo - analytic [N]")
        bottom.set_xlabel("t [s]" if traces["time"] else "sample")
    axes[0, 0].legend()
    fig.suptitle(f"{result.name}: actuator forces, MuJoCo vs analytic")
    return fig


def write_report(out_dir: Path, crane: Crane, results: list[CaseResult], tolerances: Tolerances) -> list[Path]:
    """Write report.json, table.md and forces_<case>.png into ``out_dir``, atomically."""
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    report = json.dumps(report_dict(crane, results, tolerances), indent=2)
    table = markdown_table(results, tolerances)
    for name, text in (("report.json", report), ("table.md", table)):
        path = out_dir / name
        write_atomic(path, text)
        written.append(path)
    for result in results:
        path = out_dir / f"forces_{result.name.replace('+', '_')}.png"
        fig = plot_case(result)
        save_png(fig, path, dpi=110)
        written.append(path)
    return written

"""The one reading of ``simulation.json``: the design report's closed-loop table is the table ``simulate`` prints."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from hiab_sim.design_report.analysis import closed_loop
from hiab_sim.design_report.simulation_table import markdown_table


def _run(payload_error: float, energy: float, **extra: Any) -> dict[str, Any]:
    """One run's entry of ``simulation.json`` with the fields the table reads."""
    return {
        "payload_error": payload_error,
        "predicted_net_electrical_energy_J": 1000.0,
        "net_electrical_energy_J": energy,
        "energy_difference_percent": 100.0 * (energy / 1000.0 - 1.0),
        "tcp_error_mm": {"rms": 0.25, "max": 0.75},
        "current_limit_fraction": 0.015,
        "voltage_limit_fraction": 0.0,
        **extra,
    }


#: A duty mix's report: two tasks, the second's optimal design also at an end mass 20 % heavier.
MIX = {
    "tasks": [
        {"task": "digging", "weight": 1.0, "designs": {"optimal": _run(0.0, 1002.0)}},
        {
            "task": "grading",
            "weight": 2.0,
            "designs": {
                "initial": _run(0.0, 999.0, energy_difference_to_5ms_grid_percent=-0.01),
                "optimal": {**_run(0.2, 1210.0, extra_energy_J=12.3), "nominal": _run(0.0, 997.7)},
            },
        },
    ]
}


def test_the_design_report_shows_the_rows_simulate_prints(tmp_path: Path) -> None:
    """Cell for cell the console's rows (a task column, the nominal run first), and each task's energy figure."""
    (tmp_path / "simulation.json").write_text(json.dumps(MIX), encoding="utf-8")
    for k in range(2):
        (tmp_path / f"closed_loop_energy_task{k}.png").write_bytes(b"png")
    page = closed_loop(tmp_path)
    html_rows = [re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", row) for row in re.findall(r"<tr>(.*?)</tr>", page)]
    printed = markdown_table(MIX).splitlines()
    console_rows = [[cell.strip() for cell in line.strip("|").split("|")] for line in printed[:1] + printed[2:]]
    assert html_rows == console_rows
    assert html_rows[0][0] == "task" and html_rows[0][-1] == "extra energy [J]"
    assert html_rows[3] == [
        "grading", "optimal", "planned", "1000.0", "997.7", "-0.23 %", "", "0.25 / 0.75", "1.5 %", "0.0 %", "",
    ]  # fmt: skip
    assert html_rows[4][:4] == ["grading", "optimal", "+20 %", "1000.0"] and html_rows[4][-1] == "+12.3"
    assert "Cumulative energy of task digging" in page and "Cumulative energy of task grading" in page

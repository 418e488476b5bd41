"""The closing lines ``hiab-sim simulate`` prints for a crane's or a machine's closed loop: the answer per design."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any


def closing_lines(report: dict[str, object]) -> list[str]:
    """The answer in words: per design the closed loop against the plan, and what a heavier end mass costs."""
    designs = report["designs"]
    assert isinstance(designs, dict)
    lines = []
    for design, entry in designs.items():
        rows = [entry["nominal"], entry] if "nominal" in entry else [entry]
        planned = rows[0]
        fine = planned.get("energy_difference_to_5ms_grid_percent")
        text = (
            f"{design}: the closed loop uses {planned['energy_difference_percent']:+.2f} % energy against the plan"
            + ("" if fine is None else f" ({fine:+.2f} % against the planner's energy of the plan on a 5 ms grid)")
            + f", tracking within {planned['tcp_error_mm']['max']:.2f} mm"
        )
        if len(rows) == 2:
            heavy = rows[1]
            text += (
                f"; with the end mass +{100 * heavy['payload_error']:g} % it needs {heavy['extra_energy_J']:.0f} J "
                f"more ({heavy['energy_difference_percent']:+.2f} % against the plan: the heavier load's energy, "
                f"not a failure), tracking within {heavy['tcp_error_mm']['max']:.2f} mm"
            )
        lines.append(text + ".")
        check = planned.get("bandwidth_check") or {}
        if check:
            lines.append(bandwidth_line(design, check))
    boundary = report.get("energy_boundary")
    if boundary is not None:
        lines.append(f"Energy boundary: {boundary}.")
    return lines


def bandwidth_line(design: str, check: Mapping[str, Any]) -> str:
    """One line of a run's ``bandwidth_check``: f_v against f_1, their ratio and whether 1 - f_v / (f_1 / 3) >= 0."""
    f_v = float(check["velocity_loop_bandwidth_Hz"])
    margin, f_1 = check.get("bandwidth_margin"), check.get("first_natural_frequency_Hz")
    if margin is None or f_1 is None:
        reason = check.get("note", "the EMLA file has no screw and drive_stiffness data for the natural frequencies")
        return f"{design}: velocity loop {f_v:.2f} Hz; no bandwidth check ({reason})."
    margin, f_1 = float(margin), float(f_1)
    verdict = (
        "holds: 1 - f_v / (f_1 / 3) >= 0"
        if margin >= 0.0
        else f"FAILS 1 - f_v / (f_1 / 3) >= 0: too close to the structure's resonance, at most {f_1 / 3.0:.2f} Hz"
    )
    return (
        f"{design}: velocity loop {f_v:.2f} Hz against the structure's lowest natural frequency {f_1:.2f} Hz on "
        f"the plan (ratio {f_v / f_1:.2f}, at most 1/3): bandwidth_margin {margin:+.2f} ({verdict})."
    )

"""The closing lines ``hiab-sim simulate`` prints for a crane's or a machine's closed loop: the answer per design."""

from __future__ import annotations


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
        if check.get("bandwidth_margin") is not None:
            margin = check["bandwidth_margin"]
            lines.append(
                f"{design}: velocity loop {check['velocity_loop_bandwidth_Hz']:.2f} Hz against the structure's lowest "
                f"natural frequency {check['first_natural_frequency_Hz']:.2f} Hz on the plan: bandwidth_margin "
                f"{margin:+.2f} ({'holds' if margin >= 0.0 else 'FAILS'}: 1 - f_v / (f_1 / 3) >= 0)."
            )
        elif check:
            reason = check.get(
                "note", "the EMLA file has no screw and drive_stiffness data for the natural frequencies"
            )
            lines.append(
                f"{design}: velocity loop {check['velocity_loop_bandwidth_Hz']:.2f} Hz; no bandwidth check ({reason})."
            )
    boundary = report.get("energy_boundary")
    if boundary is not None:
        lines.append(f"Energy boundary: {boundary}.")
    return lines

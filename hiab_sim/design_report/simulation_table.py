"""The runs of ``simulation.json`` (``hiab-sim simulate``) as groups, table rows and file suffixes.

One reading for the console's table (docs/results/closed-loop.md), its closing lines and the design
report's closed-loop section: a duty mix's report holds ``tasks`` (per task its ``designs``), a single
task's ``designs``; per design the run at the planned end mass comes first (the entry's ``nominal``
where the run has an end-mass error), then the run itself; the files of a mix's task k (figures,
videos) carry ``_task<k>`` before the extension, k the task's place in the result.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any, NamedTuple

#: The table's columns of one run (a duty mix's table has a ``task`` column first).
COLUMNS = (
    "design",
    "end mass",
    "predicted energy [J]",
    "closed-loop energy [J]",
    "difference",
    "vs 5 ms grid",
    "TCP error rms / max [mm]",
    "at current limit",
    "at voltage limit",
    "extra energy [J]",
)
#: The columns of :data:`COLUMNS` that hold numbers (right-aligned).
NUMERIC = tuple(range(2, len(COLUMNS)))


class RunGroup(NamedTuple):
    """The runs of one task: its files' suffix, its name (None for a single task) and its ``designs``."""

    suffix: str
    task: str | None
    designs: dict[str, Any]


def task_suffix(k: int | None) -> str:
    """The suffix of a task's files: ``_task<k>`` for a duty mix's task k, ``""`` for a single task (None)."""
    return "" if k is None else f"_task{k}"


def run_groups(report: Mapping[str, object]) -> Iterator[RunGroup]:
    """The groups of a ``simulation.json``: one per duty mix task, in the result's order, or the single task's."""
    tasks = report.get("tasks")
    if isinstance(tasks, list):
        for k, group in enumerate(tasks):
            yield RunGroup(task_suffix(k), group["task"], group["designs"])
        return
    designs = report["designs"]
    assert isinstance(designs, dict)
    yield RunGroup(task_suffix(None), None, designs)


def entry_runs(entry: Mapping[str, Any]) -> list[Mapping[str, Any]]:
    """A design's runs: the one at the planned end mass first (``nominal`` where there is one), then the entry's."""
    return [entry["nominal"], entry] if "nominal" in entry else [entry]


def run_cells(design: str, row: Mapping[str, Any]) -> tuple[str, ...]:
    """One run's cells under :data:`COLUMNS` (an empty cell where the run has no such value)."""
    tcp = row["tcp_error_mm"]
    fine = row.get("energy_difference_to_5ms_grid_percent")
    return (
        design,
        "planned" if row["payload_error"] == 0 else f"+{100 * row['payload_error']:g} %",
        f"{row['predicted_net_electrical_energy_J']:.1f}",
        f"{row['net_electrical_energy_J']:.1f}",
        f"{row['energy_difference_percent']:+.2f} %",
        "" if fine is None else f"{fine:+.2f} %",
        f"{tcp['rms']:.2f} / {tcp['max']:.2f}",
        f"{100 * row['current_limit_fraction']:.1f} %",
        f"{100 * row['voltage_limit_fraction']:.1f} %",
        "" if "extra_energy_J" not in row else f"{row['extra_energy_J']:+.1f}",
    )


def table_header(report: Mapping[str, object]) -> tuple[str, ...]:
    """The table's header: :data:`COLUMNS`, after a ``task`` column for a duty mix's report."""
    return ("task", *COLUMNS) if "tasks" in report else COLUMNS


def table_rows(report: Mapping[str, object]) -> list[tuple[str, ...]]:
    """One row per run under :func:`table_header`: per task (a duty mix's) and design, each against its task's plan."""
    return [
        (() if group.task is None else (group.task,)) + run_cells(design, row)
        for group in run_groups(report)
        for design, entry in group.designs.items()
        for row in entry_runs(entry)
    ]


def markdown_table(report: Mapping[str, object]) -> str:
    """The Markdown table of predicted against closed-loop energy and tracking (docs/results/closed-loop.md)."""
    header = table_header(report)
    shift = len(header) - len(COLUMNS)
    align = ["---:" if i - shift in NUMERIC else "---" for i in range(len(header))]
    lines = [_markdown_line(header), "|" + "|".join(align) + "|"]
    return "\n".join(lines + [_markdown_line(row) for row in table_rows(report)])


def _markdown_line(cells: tuple[str, ...]) -> str:
    """``| a | b |``, an empty cell as ``|  |``."""
    return "| " + " | ".join(cells) + " |"

"""The ``result.json`` and ``trajectory.npz`` reference, generated from the result types."""

from __future__ import annotations


def result_schema_markdown() -> str:
    """Placeholder."""
    return "# result.json and trajectory.npz\n"

"""The catalogue of the test suite's checks: every test function's docstring, grouped by test module."""

from __future__ import annotations

import ast
from pathlib import Path


def _first_line(text: str | None) -> str:
    return "" if not text else " ".join(text.strip().split("\n\n")[0].split())


def check_catalogue_markdown(tests_folder: Path) -> str:
    """A section per ``tests/test_*.py``: the module's docstring, then one line per test (name, docstring)."""
    parts = [
        "# Test catalogue",
        "",
        "Every check the test suite makes, generated from the tests' own docstrings (one line per test "
        "function; a parametrised test counts once). Tests marked `slow` run with `bash scripts/test.sh -m slow`.",
    ]
    for path in sorted(tests_folder.glob("test_*.py")):
        tree = ast.parse(path.read_text())
        tests = [
            node
            for node in ast.walk(tree)
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.name.startswith("test_")
        ]
        if not tests:
            continue
        parts += ["", f"## `{path.name}`", ""]
        doc = _first_line(ast.get_docstring(tree))
        if doc:
            parts += [doc, ""]
        for node in tests:
            slow = any("slow" in ast.unparse(d) for d in node.decorator_list)
            text = _first_line(ast.get_docstring(node)) or "(no docstring)"
            parts.append(f"- `{node.name}`{' (slow)' if slow else ''}: {text}")
    return "\n".join(parts) + "\n"

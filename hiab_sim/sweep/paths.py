"""Dotted paths into a YAML mapping: ``bounds.lift.up``, ``payload``, ``bounds.lift.up[0]``."""

from __future__ import annotations

import re
from typing import Any

from hiab_sim.errors import ConfigError

_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$")
_INDEX = re.compile(r"\[(\d+)\]")


def parse_path(path: str) -> list[str | int]:
    """Split ``a.b[1].c`` into ``["a", "b", 1, "c"]``; a malformed path raises ConfigError naming it."""
    steps: list[str | int] = []
    for part in str(path).split("."):
        match = _PART.match(part)
        if match is None:
            raise ConfigError(f"{path}: not a dotted path (expected names and [index], e.g. bounds.lift.up[0])")
        steps.append(match.group(1))
        steps += [int(i) for i in _INDEX.findall(match.group(2))]
    return steps


def set_path(document: dict[str, Any], path: str, value: Any, steps: list[str | int] | None = None) -> None:
    """Set ``path`` in ``document`` in place.

    A missing mapping key on the way is created (the loader then rejects keys it does not know);
    a list index must exist. A value written as ``{value: ..., source: ...}`` (the EMLA files)
    gets its ``value`` replaced and ``source`` set to ``"model: set by a sweep"``.
    """
    steps = parse_path(path) if steps is None else steps
    node: Any = document
    for k, step in enumerate(steps):
        last = k == len(steps) - 1
        if isinstance(step, int):
            if not isinstance(node, list) or not 0 <= step < len(node):
                raise ConfigError(f"{path}: no list item [{step}] there")
            if last:
                node[step] = value
                return
            node = node[step]
            continue
        if not isinstance(node, dict):
            raise ConfigError(f"{path}: {step!r} is below a value that is not a mapping")
        if last:
            if isinstance(node.get(step), dict) and "value" in node[step]:
                node[step] = {**node[step], "value": value, "source": "model: set by a sweep"}
            else:
                node[step] = value
            return
        if step not in node:
            node[step] = [] if isinstance(steps[k + 1], int) else {}
        node = node[step]

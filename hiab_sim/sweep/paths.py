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
    a list index must exist, in a list the document has: an index below a missing key names that
    key and the two ways to sweep it (a setting left to its default, e.g. a crane study's
    ``bounds.joint_velocity``, is not filled in from the default: give it in the file first). A
    value written as ``{value: ..., source: ...}`` (the EMLA files) gets its ``value`` replaced and
    ``source`` set to ``"model: set by a sweep"``.
    """
    steps = parse_path(path) if steps is None else steps
    node: Any = document
    missing: str | None = None  # the first key on the way the document does not have
    for k, step in enumerate(steps):
        last = k == len(steps) - 1
        if isinstance(step, int):
            if missing is not None:
                raise ConfigError(
                    f"{path}: {missing} is not in the file, so it has no item [{step}]; to sweep one item, give "
                    f"{missing} in the file (its default, if it has one), or sweep {missing} as a whole"
                )
            if not isinstance(node, list):
                raise ConfigError(f"{path}: {_dotted(steps[:k])} is not a list, so it has no item [{step}]")
            if not 0 <= step < len(node):
                items = f"{len(node)} items, [0] to [{len(node) - 1}]" if node else "no items"
                raise ConfigError(f"{path}: {_dotted(steps[:k])} has {items}")
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
            missing = missing or _dotted(steps[: k + 1])
            node[step] = [] if isinstance(steps[k + 1], int) else {}
        node = node[step]


def _dotted(steps: list[str | int]) -> str:
    """``["a", "b", 1]`` as ``a.b[1]``."""
    return "".join(f"[{s}]" if isinstance(s, int) else f".{s}" for s in steps).lstrip(".")

"""A dataclass's fields as documented keys: type, default, description and unit from the class, ranges from its checks.

The description is the field's entry under ``Attributes:`` in the class docstring (Google style), the
unit the first ``[...]`` in it; the allowed range is read from the ``check_range`` / ``check_positive`` /
``check_non_negative`` / ``check_choice`` calls of ``__post_init__`` that test ``self.<field>`` and the
tables of its ``check_fields`` calls (:func:`checked_ranges`), or from the field name each check reports
(:func:`checked_fields`, for a dataclass that checks the keys of its parts), so the reference states exactly
what the code enforces.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import math
import re
import textwrap
from typing import Any

UNIT = re.compile(r"\[([^\]]+)\]")


def attribute_docs(cls: type) -> dict[str, str]:
    """``name -> description`` from the ``Attributes:`` section of ``cls``'s docstring."""
    doc = inspect.getdoc(cls) or ""
    out: dict[str, str] = {}
    inside, current = False, None
    for line in doc.splitlines():
        if line.strip() == "Attributes:":
            inside = True
            continue
        if not inside:
            continue
        if line and not line.startswith(" "):
            break
        match = re.match(r"^ {4}(\w+)(?: \([^)]*\))?: (.*)$", line)
        if match:
            current = match.group(1)
            out[current] = match.group(2).strip()
        elif current and line.strip():
            out[current] += " " + line.strip()
    return out


def _literal(node: ast.expr, namespace: dict[str, Any]) -> Any:
    """A call argument's value: a literal, a module-level constant of ``namespace`` (``JOINT_KINDS``), else its text."""
    try:
        return ast.literal_eval(node)
    except ValueError:
        if isinstance(node, ast.Name) and isinstance(namespace.get(node.id), tuple | int | float | str):
            return namespace[node.id]
        return ast.unparse(node)


def _interval(args: list[Any], keywords: dict[str, Any]) -> str:
    low = args[0] if len(args) > 0 else keywords.get("low")
    high = args[1] if len(args) > 1 else keywords.get("high")
    low_open, high_open = keywords.get("low_open", False), keywords.get("high_open", False)
    integer = " (integer)" if keywords.get("integral") else ""
    show = lambda v: f"{v:g}" if isinstance(v, int | float) else str(v).replace("self.", "")  # noqa: E731
    if low is not None and high is not None:
        return f"{'(' if low_open else '['}{show(low)}, {show(high)}{')' if high_open else ']'}{integer}"
    if low is not None:
        return f"{'>' if low_open else '>='} {show(low)}{integer}"
    if high is not None:
        return f"{'<' if high_open else '<='} {show(high)}{integer}"
    return "finite" + integer


def _allowed(name: str, args: list[Any], keywords: dict[str, Any]) -> str | None:
    """The range a check of :mod:`hiab_sim.checks` (or a vector/interval check) enforces, in words."""
    if name == "check_range":
        return _interval(args, keywords)
    if name == "check_positive":
        return "> 0"
    if name == "check_non_negative":
        return ">= 0"
    if name == "check_choice" and args:
        choices = args[0]
        return "one of " + ", ".join(f"`{c}`" for c in choices) if isinstance(choices, tuple) else str(choices)
    if name == "check_vector":
        return "finite"
    if name == "check_interval":
        return "[min, max], finite, min < max"
    return None


def _checks(cls: type) -> list[tuple[ast.Call, str, str]]:
    """The check calls of ``cls.__post_init__``: (call, the check's name, the range in words)."""
    method = cls.__dict__.get("__post_init__")
    if method is None:
        return []
    module = inspect.getmodule(cls)
    namespace = vars(module) if module is not None else {}
    tree = ast.parse(textwrap.dedent(inspect.getsource(method)))
    out = []
    for call in ast.walk(tree):
        if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and len(call.args) >= 2):
            continue
        args = [_literal(a, namespace) for a in call.args[2:]]
        keywords = {k.arg: _literal(k.value, namespace) for k in call.keywords if k.arg}
        allowed = _allowed(call.func.id, args, keywords)
        if allowed is not None:
            out.append((call, call.func.id, allowed))
    return out


#: The tables of :func:`hiab_sim.checks.check_fields` and the range each one's fields must lie in.
FIELD_TABLES = {"positive": "> 0", "non_negative": ">= 0"}


def _table_ranges(cls: type) -> dict[str, str]:
    """``field -> allowed range`` from the ``positive`` / ``non_negative`` tables of ``check_fields`` calls."""
    method = cls.__dict__.get("__post_init__")
    if method is None:
        return {}
    out: dict[str, str] = {}
    for call in ast.walk(ast.parse(textwrap.dedent(inspect.getsource(method)))):
        if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id == "check_fields"):
            continue
        for keyword in call.keywords:
            if keyword.arg in FIELD_TABLES and isinstance(keyword.value, ast.Dict):
                for key in keyword.value.keys:
                    if isinstance(key, ast.Constant) and isinstance(key.value, str):
                        out[key.value] = FIELD_TABLES[keyword.arg]
    return out


def checked_ranges(cls: type) -> dict[str, str]:
    """``field -> allowed range`` from the range checks of ``cls.__post_init__`` on ``self.<field>``."""
    out = _table_ranges(cls)
    for call, check, allowed in _checks(cls):
        if check in ("check_vector", "check_interval"):
            continue  # reported by checked_fields under the name they check
        target = call.args[1]
        if isinstance(target, ast.Call) and target.args:  # e.g. math.degrees(self.x): reported in its own key
            target = target.args[0]
        if isinstance(target, ast.Attribute) and isinstance(target.value, ast.Name) and target.value.id == "self":
            out[target.attr] = allowed
    return out


def checked_fields(cls: type) -> dict[str, str]:
    """``named field -> allowed range`` from the checks of ``cls.__post_init__``, by the name each error gives.

    A check names the file key it tests (``check_positive(f"{where}.actuator.stroke", ...)``): the
    name's text after its last ``{...}`` (leading dot dropped) is the key path below ``where``;
    a name ending in a ``{...}`` (a loop over keys) is skipped.
    """
    out: dict[str, str] = {}
    for call, _, allowed in _checks(cls):
        name = call.args[0]
        if isinstance(name, ast.Constant) and isinstance(name.value, str):
            out[name.value] = allowed
        elif isinstance(name, ast.JoinedStr) and name.values and isinstance(name.values[-1], ast.Constant):
            tail = str(name.values[-1].value).lstrip(".")
            if tail:
                out[tail] = allowed
    return out


def _type_name(annotation: Any) -> str:
    text = annotation if isinstance(annotation, str) else getattr(annotation, "__name__", str(annotation))
    text = text.replace(" | None", "")
    return {"float": "number", "int": "integer", "str": "text", "bool": "true/false"}.get(
        text,
        text.replace("tuple[float, float, float]", "[number, number, number]").replace(
            "tuple[float, float]", "[number, number]"
        ),
    )


def _default(field: dataclasses.Field[Any]) -> str:
    if field.default is dataclasses.MISSING and field.default_factory is dataclasses.MISSING:
        return "required"
    if field.default is dataclasses.MISSING:
        return "(built in)"
    value = field.default
    if value is None:
        return "none"
    if isinstance(value, float):
        return f"{value:g}" if math.isfinite(value) else str(value)
    if isinstance(value, tuple):
        return "[" + ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return str(value)


def field_rows(cls: type, skip: tuple[str, ...] = ("label",)) -> dict[str, dict[str, str]]:
    """``field -> {type, unit, default, allowed, description}`` for the init fields of dataclass ``cls``."""
    docs, ranges = attribute_docs(cls), checked_ranges(cls)
    rows: dict[str, dict[str, str]] = {}
    for field in dataclasses.fields(cls):
        if field.name in skip or not field.init:
            continue
        description = docs.get(field.name, "")
        unit = UNIT.search(description)
        rows[field.name] = {
            "type": _type_name(field.type),
            "unit": unit.group(1) if unit else "",
            "default": _default(field),
            "allowed": ranges.get(field.name, ""),
            "description": description,
        }
    return rows

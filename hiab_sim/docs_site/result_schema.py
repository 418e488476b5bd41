"""The ``result.json`` and ``trajectory.npz`` reference, generated from the result types.

``result.json`` is walked from :class:`hiab_sim.results.schema.Result` through the type hints of its
dataclasses: every key with its type, its unit (from the name's suffix, as the project's naming rule
states it), the section's docstring and the field's own comment. ``trajectory.npz``'s arrays are
listed from their declared schema, :data:`hiab_sim.results.trajectory_file.ARRAYS` (the writer refuses
arrays that lack a declared key, and a test holds a written file to it).
"""

from __future__ import annotations

import dataclasses
import inspect
import re
import types
import typing
from typing import Any

from hiab_sim.docs_site.markdown import table

#: Unit of a key by its name's suffix (the project's rule: a name states its unit).
SUFFIX_UNITS = (
    ("_W2s", "W^2 s"),
    ("_J", "J"),
    ("_kJ", "kJ"),
    ("_W", "W"),
    ("_N", "N"),
    ("_Nm", "N m"),
    ("_m_per_s", "m/s"),
    ("_mm", "mm"),
    ("_m", "m"),
    ("_s", "s"),
    ("_K", "K"),
    ("_C", "deg C"),
    ("_deg", "deg"),
    ("_Hz", "Hz"),
    ("_percent", "%"),
)


def unit_of(name: str) -> str:
    """The unit a key's name states (empty when it states none)."""
    return next((unit for suffix, unit in SUFFIX_UNITS if name.endswith(suffix)), "")


def _comments(cls: type) -> dict[str, str]:
    out = {}
    for line in inspect.getsource(cls).splitlines():
        match = re.match(r"^\s{4}(\w+): [^#]+#\s*(.+)$", line)
        if match:
            out[match.group(1)] = match.group(2).strip()
    return out


def _inner(tp: Any) -> list[Any]:
    """The dataclasses a type hint contains (through Optional, tuple, dict)."""
    if dataclasses.is_dataclass(tp):
        return [tp]
    return [d for arg in typing.get_args(tp) for d in _inner(arg)]


def _type_text(tp: Any) -> str:
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        return "object"
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (typing.Union, types.UnionType):
        kept = [a for a in args if a is not type(None)]
        return " or ".join(_type_text(a) for a in kept) + (" or null" if len(kept) < len(args) else "")
    if origin is tuple:
        return f"list of {_type_text(args[0])}" if args else "list"
    if origin is dict:
        return f"mapping to {_type_text(args[1])}" if args else "mapping"
    return {float: "number", int: "integer", str: "text", bool: "true/false"}.get(tp, getattr(tp, "__name__", str(tp)))


def result_rows(
    cls: type, prefix: str = "", unit: str = "", seen: frozenset[type] = frozenset()
) -> list[tuple[str, str, str, str]]:
    """(key path, type, unit, description) for every key below ``cls``; lists as ``key[]``, mappings as ``key.*``.

    A key whose name states no unit takes its section's (``energy_breakdown_J.copper`` is in J).
    """
    hints = typing.get_type_hints(cls)
    comments = _comments(cls)
    rows = []
    for field in dataclasses.fields(cls):
        if field.name == "extra":
            continue
        tp = hints[field.name]
        path = f"{prefix}{field.name}"
        own = unit_of(field.name) or unit
        inner = [d for d in _inner(tp) if d not in seen]
        text = _type_text(tp)
        comment = comments.get(field.name, "")
        if not inner:
            rows.append((path, text, own if "number" in text else "", comment))
            continue
        child = inner[0]
        doc = (inspect.getdoc(child) or "").split("\n\n")[0].replace("\n", " ")
        rows.append((path, text.replace("object", child.__name__), "", " ".join(filter(None, (comment, doc)))))
        sep = "[]." if text.startswith("list") else (".*." if text.startswith("mapping") else ".")
        rows += result_rows(child, f"{path}{sep}", own, seen | {child})
    return rows


def result_schema_markdown() -> str:
    """The page: result.json's keys from the result types, then trajectory.npz's arrays."""
    from hiab_sim.results.schema import SCHEMA_VERSION, Result
    from hiab_sim.results.trajectory_file import ARRAYS, VERSION_KEY
    from hiab_sim.results.trajectory_file import SCHEMA_VERSION as ARRAYS_VERSION

    rows = [(f"`{p}`", t, u, d) for p, t, u, d in result_rows(Result)]
    arrays = [(f"`{spec.key}`", f"({spec.shape})", spec.unit, spec.description) for spec in ARRAYS]
    return (
        "\n".join(
            [
                "# result.json and trajectory.npz",
                "",
                f"`hiab-sim optimize` writes `result.json` (schema version {SCHEMA_VERSION}) and `trajectory.npz` "
                "into the result folder; `hiab_sim.results.read.read_result(folder)` reads the first back as "
                "frozen dataclasses with the same names. The table is generated from those dataclasses "
                "(`hiab_sim/results/`): `a[]` is an element of the list `a`, `a.*` any key of the mapping `a` "
                "(actuator, design or task names). Units follow from each name's suffix; costs of eq. `costf2` are "
                "in W^2 s (a squared power integrated over time, not an energy). Link lengths are written as "
                "`{lift: {L, Lc0, Lc}, tilt: {...}}` in m. Optional sections are absent from results that do not "
                "have them.",
                "",
                "## result.json",
                "",
                table(("key", "type", "unit", "description"), rows),
                "",
                "## trajectory.npz",
                "",
                f"NumPy arrays on the fine re-check grid (K samples, J joints, A actuators; `{{design}}` is "
                f"`initial` or `optimal`), array schema version {ARRAYS_VERSION} in `{VERSION_KEY}`. A duty mix "
                "writes each task's arrays with the prefix `task<k>_` (k = 0, 1, ... in the order of `tasks:`); "
                "`hiab_sim.results.read.open_run(folder, Result)` reads both files.",
                "",
                table(("array", "shape", "unit", "content"), arrays),
            ]
        )
        + "\n"
    )

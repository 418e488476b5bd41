"""JSON <-> frozen dataclasses, driven by the dataclasses' own type hints (for ``result.json``).

:func:`to_json` turns a dataclass tree into JSON-ready dicts, lists and scalars; :func:`from_json`
builds the tree back, checking every value against its field's type and naming the dotted path of
the first missing or mistyped key (:class:`~hiab_sim.errors.ConfigError`). Supported field
types: ``bool``, ``int``, ``float`` (an int is accepted), ``str``, ``Any`` (kept as read), ``X |
None``, a union of dataclasses (told apart by their keys), ``tuple[X, ...]``, ``list[X]``,
``dict[str, X]`` and nested dataclasses.

Two conventions let a format grow without breaking files written before:

* a field made with :func:`optional` defaults to None and is left out of the JSON while None, so a
  section added later is simply absent from older files (and from results that do not have it);
* a dataclass with a field named ``extra`` (``dict[str, Any]``) keeps every key it does not know
  there and writes it back, so a file from a newer version round-trips; other dataclasses ignore
  keys they do not know.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from typing import Any, TypeVar

from hiab_sim.errors import ConfigError

T = TypeVar("T")
#: Field metadata: leave the key out of the JSON while the value is None.
OMIT_NONE = "omit_none"
#: Name of the field that keeps the keys a dataclass does not know.
EXTRA = "extra"


def optional() -> Any:
    """A field that defaults to None and is written only when set (a section later versions add)."""
    return dataclasses.field(default=None, metadata={OMIT_NONE: True})


def to_json(value: Any) -> Any:
    """JSON-ready form of a dataclass tree (dicts, lists, str, int, float, bool, None)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        out: dict[str, Any] = {}
        for f in dataclasses.fields(value):
            item = getattr(value, f.name)
            if f.name == EXTRA:
                out.update({k: to_json(v) for k, v in item.items()})
            elif not (item is None and f.metadata.get(OMIT_NONE)):
                out[f.name] = to_json(item)
        return out
    if isinstance(value, dict):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_json(v) for v in value]
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value)
    if hasattr(value, "tolist"):  # a numpy scalar or array
        return to_json(value.tolist())
    raise TypeError(f"cannot write {type(value).__name__} as JSON")


def from_json(cls: type[T], data: Any, path: str = "") -> T:
    """Build dataclass ``cls`` from JSON data; ConfigError names the dotted path of a bad key."""
    if not isinstance(data, dict):
        raise ConfigError(f"'{path or '.'}' must be a mapping, got {_kind(data)}")
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    values: dict[str, Any] = {}
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        if f.name == EXTRA:
            values[EXTRA] = {k: v for k, v in data.items() if k not in names}
            continue
        where = f"{path}.{f.name}" if path else f.name
        if f.name in data:
            values[f.name] = _decode(hints[f.name], data[f.name], where)
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ConfigError(f"missing '{where}'")
    return cls(**values)


def _decode(kind: Any, value: Any, path: str) -> Any:
    origin = typing.get_origin(kind)
    args = typing.get_args(kind)
    if kind is Any:
        return value
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        options = [a for a in args if a is not type(None)]
        if len(options) != 1:
            return _decode(_dataclass_by_keys(options, value, path), value, path)
        return _decode(options[0], value, path)
    if dataclasses.is_dataclass(kind):
        return from_json(kind, value, path)  # type: ignore[arg-type]
    if origin in (tuple, list):
        if not isinstance(value, list):
            raise ConfigError(f"'{path}' must be a list, got {_kind(value)}")
        item = args[0]
        items = [_decode(item, v, f"{path}[{i}]") for i, v in enumerate(value)]
        return tuple(items) if origin is tuple else items
    if origin is dict:
        if not isinstance(value, dict):
            raise ConfigError(f"'{path}' must be a mapping, got {_kind(value)}")
        return {str(k): _decode(args[1], v, f"{path}.{k}") for k, v in value.items()}
    if kind is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"'{path}' must be true or false, got {_kind(value)}")
        return value
    if kind is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"'{path}' must be an integer, got {_kind(value)}")
        return value
    if kind is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(f"'{path}' must be a number, got {_kind(value)}")
        return float(value)
    if kind is str:
        if not isinstance(value, str):
            raise ConfigError(f"'{path}' must be a string, got {_kind(value)}")
        return value
    raise TypeError(f"{path}: unsupported field type {kind}")


def _dataclass_by_keys(options: list[Any], value: Any, path: str) -> Any:
    """The one dataclass of a union whose field names are the mapping's keys (``A | B | None`` of dataclasses)."""
    if not all(dataclasses.is_dataclass(o) for o in options):
        raise TypeError(f"{path}: a union must be 'X | None' or of dataclasses, got {options}")
    if not isinstance(value, dict):
        raise ConfigError(f"'{path}' must be a mapping, got {_kind(value)}")
    for option in options:
        if {f.name for f in dataclasses.fields(option)} == set(value):
            return option
    names = " or ".join(str(sorted(f.name for f in dataclasses.fields(o))) for o in options)
    raise ConfigError(f"'{path}' must have the keys {names}, got {sorted(value)}")


def _kind(value: Any) -> str:
    return "null" if value is None else f"{type(value).__name__} {value!r}"[:60]

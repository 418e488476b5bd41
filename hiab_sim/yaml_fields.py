"""The one field reader: YAML text -> checked Python values, with errors that name the field.

Every configuration file (crane, EMLA set, study, validation cases) is read here: the structure
and the types (unknown or missing keys, a word where a number belongs) raise
:class:`~hiab_sim.errors.ConfigError`; the ranges are checked once, by the frozen dataclass the
values build (its ``__post_init__``, with :func:`check_range`), and raise
:class:`~hiab_sim.errors.InvalidInputError` naming field, value, allowed range and unit.
Defaults are the dataclasses' own: :func:`section` passes only the keys a file gives.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any

import yaml

from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import Source

#: The safe loader every file goes through: libyaml's parser where PyYAML was built with it (the same
#: documents as the pure-Python parser, about 9x faster on the shipped files), the pure-Python one otherwise.
SafeLoader: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def parse_yaml(text: str, loader: type[yaml.SafeLoader] = SafeLoader) -> Any:
    """YAML text -> Python values with the safe loader (or a subclass of it); raises ``yaml.YAMLError``."""
    return yaml.load(text, Loader=loader)  # a safe loader: SafeLoader, its libyaml twin or a subclass


def duplicate_key(text: str) -> tuple[int, str, str] | None:
    """The first key given twice in one mapping of YAML ``text``, or None.

    Returns (its 1-based line, the dotted path of the mapping holding it, the key); keys compared as
    written (scalars), a sequence's items named ``[i]``.
    """

    def walk(node: yaml.Node, path: str) -> tuple[int, str, str] | None:
        if isinstance(node, yaml.MappingNode):
            seen: set[str] = set()
            for key_node, value_node in node.value:
                key = str(key_node.value)
                if key in seen:
                    return key_node.start_mark.line + 1, path, key
                seen.add(key)
                found = walk(value_node, f"{path}.{key}" if path else key)
                if found is not None:
                    return found
        elif isinstance(node, yaml.SequenceNode):
            for i, item in enumerate(node.value):
                found = walk(item, f"{path}[{i}]")
                if found is not None:
                    return found
        return None

    root = yaml.compose(text, Loader=SafeLoader)
    return None if root is None else walk(root, "")


def read_yaml(source: Source) -> Any:
    """Parse a YAML file; a missing file or malformed YAML raises :class:`ConfigError`."""
    text = source.read_text()
    try:
        return parse_yaml(text)
    except yaml.YAMLError as error:
        raise ConfigError(f"{source.label}: not valid YAML: {error}") from None


def mapping(data: Any, where: str, allowed: set[str] | None, required: set[str] | None = None) -> Mapping[str, Any]:
    """Check that ``data`` is a mapping with no unknown and no missing keys.

    Args:
        data: The parsed YAML node.
        where: Its dotted path, used in messages.
        allowed: Allowed keys (None: any key).
        required: Required keys (default: all of ``allowed``).

    """
    if not isinstance(data, Mapping):
        raise ConfigError(f"{where}: expected a mapping, got {type(data).__name__}")
    if allowed is not None:
        unknown = sorted(set(map(str, data)) - allowed)
        if unknown:
            raise ConfigError(f"{where}: unknown key(s) {unknown}; allowed: {sorted(allowed)}")
        missing = sorted((allowed if required is None else required) - set(data))
        if missing:
            raise ConfigError(f"{where}: missing key(s) {missing}")
    return data


#: Largest magnitude a number of a file may have [SI units]. The largest physical value the shipped files
#: hold is a steel's Young's modulus, 2.06e11 Pa; 1e15 leaves four orders of magnitude above it and
#: refuses a typo such as a 1e300 kg link, which would overflow the energy integrals (P^2 of its
#: forces) into a traceback instead of a one-line error.
MAGNITUDE_LIMIT = 1e15


def number(value: Any, where: str) -> float:
    """A finite number of magnitude at most :data:`MAGNITUDE_LIMIT` (bools and strings are rejected)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        hint = " (YAML reads 1e3 as text: write 1.0e+3 or 1000.0)" if isinstance(value, str) else ""
        raise ConfigError(f"{where}: expected a number, got {value!r}{hint}")
    if not math.isfinite(value):
        raise InvalidInputError(where, float(value), "must be finite")
    if abs(value) > MAGNITUDE_LIMIT:
        raise InvalidInputError(
            where,
            float(value),
            f"must be of magnitude <= {MAGNITUDE_LIMIT:g} (SI units; the largest in a shipped file is 2.06e+11)",
        )
    return float(value)


def positive(value: Any, where: str, unit: str = "") -> float:
    """A finite number > 0."""
    result = number(value, where)
    if result <= 0.0:
        raise InvalidInputError(where, result, "must be > 0", unit)
    return result


def integer(value: Any, where: str) -> int:
    """An integer (a float with an integral value is accepted; bools and strings are not)."""
    if isinstance(value, float) and value.is_integer():
        return int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(f"{where}: expected an integer, got {value!r}")
    return int(value)


def text(value: Any, where: str) -> str:
    """A string (numbers are written as text, as YAML users expect for names)."""
    if isinstance(value, Mapping | list):
        raise ConfigError(f"{where}: expected a string, got {type(value).__name__}")
    return str(value)


def vector(value: Any, where: str, size: int) -> tuple[float, ...]:
    """A list of ``size`` finite numbers."""
    if not isinstance(value, list | tuple) or len(value) != size:
        raise ConfigError(f"{where}: expected a list of {size} numbers, got {value!r}")
    return tuple(number(v, f"{where}[{i}]") for i, v in enumerate(value))


def sourced_number(node: Any, where: str, kinds: tuple[str, ...]) -> tuple[float, str]:
    """(number, provenance) from a bare number or a ``{value, source}`` mapping.

    ``source`` must be a string whose first word (before ``:``) is one of ``kinds``; a bare
    number's provenance is ``"unspecified"``.
    """
    source = "unspecified"
    if isinstance(node, Mapping):
        mapping(node, where, {"value", "source"}, {"value"})
        if "source" in node:
            source = node["source"]
            if not isinstance(source, str) or source.split(":", 1)[0].strip() not in kinds:
                raise ConfigError(
                    f"{where}.source must be a string starting with one of {', '.join(kinds)}, got {source!r}"
                )
        node = node["value"]
    return number(node, where), source


_READERS: dict[str, Callable[[Any, str], Any]] = {
    "float": number,
    "int": integer,
    "str": text,
    "tuple[float, float]": lambda v, w: vector(v, w, 2),
    "tuple[float, float, float]": lambda v, w: vector(v, w, 3),
}


def section(cls: type, data: Any, where: str, skip: tuple[str, ...] = ()) -> dict[str, Any]:
    """Read a YAML mapping as the keyword arguments of dataclass ``cls``.

    The keys are ``cls``'s fields (less ``skip``); fields without a default are required, and
    keys a file omits are left out, so the dataclass's own default applies. Each value is read
    by its annotated type (``float``, ``int``, ``str``, 2- and 3-tuples of floats, ``| None``).
    """
    fields = [f for f in dataclasses.fields(cls) if f.name not in skip and f.init]
    required = {f.name for f in fields if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING}
    node = mapping({} if data is None else data, where, {f.name for f in fields}, required)
    values: dict[str, Any] = {}
    for f in fields:
        if f.name in node:
            kind = (f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type))).replace(
                " | None", ""
            )
            if kind not in _READERS:
                raise TypeError(f"{cls.__name__}.{f.name}: no YAML reader for type {kind!r}")
            values[f.name] = _READERS[kind](node[f.name], f"{where}.{f.name}")
    return values

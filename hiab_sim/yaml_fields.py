"""Reading YAML files and checking their fields, with errors that name the field (shared by all loaders)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from hiab_sim.errors import ConfigError, InvalidInputError


def read_yaml(path: Path, what: str) -> Any:
    """Parse a YAML file; a missing file or malformed YAML raises :class:`ConfigError`."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise ConfigError(f"cannot read {what} {path}: {error.strerror or error}") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as error:
        raise ConfigError(f"{path}: not valid YAML: {error}") from None


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


def number(value: Any, where: str) -> float:
    """A finite number (bools and strings are rejected)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{where}: expected a number, got {value!r}")
    if not math.isfinite(value):
        raise InvalidInputError(where, float(value), "must be finite")
    return float(value)


def positive(value: Any, where: str, unit: str = "") -> float:
    """A finite number > 0."""
    result = number(value, where)
    if result <= 0.0:
        raise InvalidInputError(where, result, "must be > 0", unit)
    return result

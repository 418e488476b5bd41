"""Range checks for the dataclasses' ``__post_init__``: one-line errors naming field, value, allowed range and unit."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

from hiab_sim.errors import InvalidInputError


def check_range(
    where: str,
    value: Any,
    low: float | None = None,
    high: float | None = None,
    unit: str = "",
    *,
    low_open: bool = False,
    high_open: bool = False,
    integral: bool = False,
) -> None:
    """Raise :class:`InvalidInputError` unless ``value`` is a finite number in the interval.

    ``low``/``high`` None: unbounded on that side; ``*_open``: the bound itself is excluded;
    ``integral``: the value must be an ``int``. Used by the dataclasses' ``__post_init__``.
    """
    kind = "an integer" if integral else "a finite number"
    ok = not isinstance(value, bool) and isinstance(value, int if integral else int | float)
    ok = ok and math.isfinite(value)
    ok = ok and (low is None or (value > low if low_open else value >= low))
    ok = ok and (high is None or (value < high if high_open else value <= high))
    if ok:
        return
    if low is not None and high is not None:
        allowed = f"must lie in {'(' if low_open else '['}{low:.6g}, {high:.6g}{')' if high_open else ']'}"
    elif low is not None:
        allowed = f"must be {'>' if low_open else '>='} {low:.6g}"
    elif high is not None:
        allowed = f"must be {'<' if high_open else '<='} {high:.6g}"
    else:
        allowed = f"must be {kind}"
    raise InvalidInputError(where, value, allowed, unit)


def check_positive(where: str, value: Any, unit: str = "") -> None:
    """Raise :class:`InvalidInputError` unless ``value`` is a finite number > 0."""
    check_range(where, value, 0.0, unit=unit, low_open=True)


def check_non_negative(where: str, value: Any, unit: str = "") -> None:
    """Raise :class:`InvalidInputError` unless ``value`` is a finite number >= 0."""
    check_range(where, value, 0.0, unit=unit)


def check_fields(
    obj: Any,
    positive: Mapping[str, str] | None = None,
    non_negative: Mapping[str, str] | None = None,
    *,
    where: str | None = None,
) -> None:
    """Check fields of the dataclass ``obj``: each ``positive`` one > 0, each ``non_negative`` one >= 0.

    The tables map a field's name to its unit; the fields are checked in the dataclass's order with
    :func:`check_positive` / :func:`check_non_negative`, an error naming ``<where>.<field>`` (``where``
    defaults to ``obj.label``).
    """
    prefix = obj.label if where is None else where
    positive, non_negative = positive or {}, non_negative or {}
    fields = dataclasses.fields(obj)
    unknown = (positive.keys() | non_negative.keys()) - {field.name for field in fields}
    if unknown:
        raise TypeError(f"{type(obj).__name__} has no field {', '.join(sorted(unknown))}")
    for field in fields:
        name = field.name
        if name in positive:
            check_positive(f"{prefix}.{name}", getattr(obj, name), positive[name])
        elif name in non_negative:
            check_non_negative(f"{prefix}.{name}", getattr(obj, name), non_negative[name])


def check_choice(where: str, value: Any, choices: tuple[Any, ...]) -> None:
    """Raise :class:`InvalidInputError` unless ``value`` is one of ``choices`` (a bool is no number here)."""
    if value not in choices or (isinstance(value, bool) and not any(isinstance(c, bool) for c in choices)):
        raise InvalidInputError(where, value, f"must be one of {', '.join(map(str, choices))}")


def check_efficiency(where: str, value: float) -> None:
    """Raise :class:`InvalidInputError` unless ``value`` is an efficiency: a finite number in (0, 1]."""
    if not (math.isfinite(value) and 0.0 < value <= 1.0):
        raise InvalidInputError(where, value, "must be in (0, 1]")

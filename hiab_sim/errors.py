"""The project's one error hierarchy: every bad input raises a subclass of HiabSimError."""

from __future__ import annotations


class HiabSimError(Exception):
    """Base class of every error hiab-sim raises on purpose.

    The CLI catches it, prints the message on one line and exits with status 2.
    """


class InvalidInputError(HiabSimError, ValueError):
    """A value is outside its allowed range.

    The message always names the field, the offending value and the allowed range, e.g.
    ``lift.Lc = -0.1 m is out of range: must be > 0``.
    """

    def __init__(self, field: str, value: object, allowed: str, unit: str = "") -> None:
        self.field = field
        self.value = value
        self.allowed = allowed
        self.unit = unit
        unit_part = f" {unit}" if unit else ""
        super().__init__(f"{field} = {_show(value)}{unit_part} is out of range: {allowed}")


def _show(value: object) -> str:
    """The value on one line: a float to 6 digits, a string quoted, an array as its nested list."""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, str):
        return repr(value)
    tolist = getattr(value, "tolist", None)  # a numpy array prints its rows on separate lines
    return str(tolist() if callable(tolist) else value).replace("\n", " ")


class ConfigError(HiabSimError, ValueError):
    """A configuration file is malformed (unknown or missing keys, wrong types)."""


class BackendUnavailableError(HiabSimError, RuntimeError):
    """An optional system component (OpenGL backend, ffmpeg) is missing; the message says how to install it."""


class SolverError(HiabSimError, RuntimeError):
    """The optimiser failed; the partial history is kept on disk."""


class InfeasibleStudyError(HiabSimError, RuntimeError):
    """No point within the bounds satisfies every constraint; the message names the binding limit (exit 3)."""

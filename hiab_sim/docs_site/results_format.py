"""Number formats shared by the results pages' generated blocks (units in the text, SI values in the data)."""

from __future__ import annotations

from typing import Any

#: The crane's chains in the order the pages list them, with each chain's lengths (xi = [L, Lc0, Lc]).
CHAINS = ("lift", "tilt")


def lengths(values: dict[str, Any], chain: str, digits: int = 3) -> str:
    """One chain's L / Lc0 / Lc [m] of a crane design, e.g. ``1.250 / 0.300 / 0.735``."""
    xi = values[chain]
    return " / ".join(f"{xi[k]:.{digits}f}" for k in ("L", "Lc0", "Lc"))


def percent_change(before: float, after: float, digits: int = 2) -> str:
    """The relative change from ``before`` to ``after`` in %, signed, e.g. ``-3.31 %``."""
    return f"{100.0 * (after - before) / before:+.{digits}f} %"


def kilo(value: float, digits: int = 2) -> str:
    """A value in thousands of its unit: ``kilo(11453.6) == '11.45'`` (kJ for joules)."""
    return f"{value / 1e3:.{digits}f}"


def before_after(before: float, after: float, unit: str = "J", digits: int = 1) -> str:
    """``before → after unit (change)``, e.g. ``11846.2 → 11453.6 J (-3.31 %)``."""
    return f"{before:.{digits}f} → {after:.{digits}f} {unit} ({percent_change(before, after)})"

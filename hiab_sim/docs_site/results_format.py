"""Number formats shared by the results pages' generated blocks (units in the text, SI values in the data)."""

from __future__ import annotations

from typing import Any

from hiab_sim.crane.description import CHAIN_NAMES
from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.percent import change_percent

#: The crane's chains in the order the pages list them (the crane file's order), each with its lengths
#: (xi = [L, Lc0, Lc]).
CHAINS = CHAIN_NAMES
#: The XS 031's lift actuator (the first in the crane's actuator order): the results pages' prose and single
#: columns speak of its motor and force alone, as the drive that raises the whole boom with the load.
LIFT = ACTUATOR_NAMES[0]


def lengths(values: dict[str, Any], chain: str, digits: int = 3) -> str:
    """One chain's L / Lc0 / Lc [m] of a crane design, e.g. ``1.250 / 0.300 / 0.735``."""
    xi = values[chain]
    return " / ".join(f"{xi[k]:.{digits}f}" for k in ("L", "Lc0", "Lc"))


def chain_lengths(values: dict[str, Any], digits: int = 3, legend: bool = False) -> str:
    """Every chain's lengths in prose, e.g. ``lift 1.250 / 0.300 / 0.735 m, tilt 0.900 / 0.250 / 0.600 m``.

    ``legend`` names the three lengths after the first chain's name (``lift L / Lc0 / Lc = 1.250 / ...``).
    """
    return ", ".join(
        f"{c}{' L / Lc0 / Lc =' if legend and i == 0 else ''} {lengths(values, c, digits)} m"
        for i, c in enumerate(CHAINS)
    )


def length_headers(legend_once: bool = False) -> tuple[str, ...]:
    """One column header per chain for its lengths, ``lift L / Lc0 / Lc [m]``, ``tilt L / Lc0 / Lc [m]``.

    ``legend_once`` names the lengths in the first column only, the others by the chain alone (``tilt [m]``).
    """
    return tuple(f"{c} [m]" if legend_once and i > 0 else f"{c} L / Lc0 / Lc [m]" for i, c in enumerate(CHAINS))


def percent_change(before: float, after: float, digits: int = 2) -> str:
    """The relative change from ``before`` to ``after`` in %, signed, e.g. ``-3.31 %``."""
    return f"{change_percent(before, after):+.{digits}f} %"


def kilo(value: float, digits: int = 2) -> str:
    """A value in thousands of its unit: ``kilo(11453.6) == '11.45'`` (kJ for joules)."""
    return f"{value / 1e3:.{digits}f}"


def before_after(before: float, after: float, unit: str = "J", digits: int = 1) -> str:
    """``before → after unit (change)``, e.g. ``11846.2 → 11453.6 J (-3.31 %)``."""
    return f"{before:.{digits}f} → {after:.{digits}f} {unit} ({percent_change(before, after)})"

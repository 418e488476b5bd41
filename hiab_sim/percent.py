"""Relative changes and savings in percent, against the magnitude of the reference value.

An energy over a cycle can be negative: a cycle that lowers a load regenerates more than it draws,
so its net electrical energy (and, with lossless enough drives, its battery energy) is below zero.
Divided by the signed reference, a change would read a fall as a rise: -85 J -> -87 J is 2.4 % less
energy, but (-87 - -85) / -85 = +2.4 %. Every percent change and saving of the tool divides by
``|reference|``, so its sign is the change's own: a change is positive when the value rises, a saving
positive when it falls. A zero reference has no relative change: the result is inf or nan
there (numpy division, with numpy's divide warning); callers that print a change test for zero first.
"""

from __future__ import annotations

from typing import TypeVar, overload

import numpy as np

from hiab_sim.arrays import Array

#: A float or an array of them (a pandas column passes as one).
Number = TypeVar("Number", float, Array)


@overload
def change_percent(reference: float, value: float) -> float: ...
@overload
def change_percent(reference: float | Array, value: Array) -> Array: ...
@overload
def change_percent(reference: Array, value: float | Array) -> Array: ...
def change_percent(reference: float | Array, value: float | Array) -> float | Array:
    """``100 (value - reference) / |reference|`` [%]: positive when ``value`` is above ``reference``."""
    rise: float | Array = value - reference
    return 100.0 * rise / np.abs(reference)


def saving_percent(reference: Number, value: Number) -> Number:
    """``100 (reference - value) / |reference|`` [%]: positive when ``value`` is below ``reference``.

    Both of one kind (two floats, two arrays or two columns): a saving is one quantity's own, start
    against optimum, where :func:`change_percent` also sets one value against many.
    """
    fall = reference - value  # not -change_percent: a zero saving prints as 0.00, not -0.00
    return 100.0 * fall / np.abs(reference)

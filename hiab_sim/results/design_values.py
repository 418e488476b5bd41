"""The values of a design's decision variables as a result stores them: a crane file's or a machine file's.

A crane file's study stores the seed's Xi as :class:`~hiab_sim.crane.description.LinkLengths`
(``{"lift": {"L", "Lc0", "Lc"}, "tilt": {...}}`` [m]); a machine file's as
:class:`~hiab_sim.machine.design.MachineDesign` (``{"names": [...], "values": [...]}``, each value in
its variable's unit, m). The result codec tells them apart by their keys.
"""

from __future__ import annotations

import numpy as np

from hiab_sim.crane.description import LinkLengths
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.design import MachineDesign

#: A design's decision-variable values.
DesignValues = LinkLengths | MachineDesign


def with_values(design: DesignValues, values: object) -> DesignValues:
    """A design of the same kind (and names) with other values (n_xi,) [m]."""
    if isinstance(design, MachineDesign):
        return MachineDesign(design.names, tuple(float(v) for v in np.asarray(values, dtype=float).reshape(-1)))
    return LinkLengths.from_array(np.asarray(values, dtype=float))


def crane_lengths(design: DesignValues, where: str = "design") -> LinkLengths:
    """The crane's link lengths of a design (a crane file's study); a machine file's design is refused by name."""
    if not isinstance(design, LinkLengths):
        raise InvalidInputError(where, type(design).__name__, "this part of hiab-sim needs a crane file's link lengths")
    return design


def design_words(design: DesignValues, form: str = ".4f") -> str:
    """A design in one line, chain by chain, names as the design gives them: ``c1 a=.. b=..  c2 a=.. m`` [m].

    ``form``: the format of each value (``.4f``; ``g`` for a rounded, buildable design).
    """
    chains: dict[str, list[str]] = {}
    for name, value in zip(design.names, design.as_array(), strict=True):
        chain, variable = name.split(".", 1)
        chains.setdefault(chain, []).append(f"{variable}={value:{form}}")
    return "  ".join(f"{chain} {' '.join(words)}" for chain, words in chains.items()) + " m"

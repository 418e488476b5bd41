"""The stroke rows of a machine file's study: x, Lc - x, stroke - x of each stroke chain, with exact partials.

A stroke chain (a ``triangle`` or ``linkage``; a ``direct`` chain's stroke is its joint) has its stroke
x(q_j, Xi) from its joint and its own decision variables only. :class:`StrokeRows` builds each chain at a
design without building the machine around it, and without the actuator bodies' design masses
(:func:`~hiab_sim.machine.design.designed_chain` with ``bodies=False``: the geometry is the same), and keeps
the chains and the partials it computed: the robust rows' finite differences in one chain's variable ask
again for every other chain at the same values. Lengths in m, angles in rad.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.machine.chains import Chain
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import designed_chain
from hiab_sim.machine.kinematics.closure import joint_to_stroke
from hiab_sim.machine.kinematics.design_partials import stroke_design_partials

#: Entries kept per cache before it is emptied (designs and joint samples of a solve's recent points).
CACHE_SIZE = 256


def chains_with_strokes(machine: Machine) -> list[Chain]:
    """The chains with a stroke row of their own (``triangle``, ``linkage``), in the machine's order."""
    return [c for c in machine.chains if c.kind != "direct"]


def _variable_map(chain: Chain, keys: tuple[str, ...]) -> tuple[list[int], Array, Array]:
    """Per variable of a stroke chain: its column in Xi, whether it moves the stroke (1 or 0), d(rod)/dv.

    With the retracted length x0 a variable, the piston offset Lc0 moves only the rod (rod = x0 - Lc0).
    """
    retracted = any(v.kind == "retracted_length" for v in chain.variables)
    columns = [keys.index(v.key) for v in chain.variables]
    moves = np.array([0.0 if v.kind == "piston_offset" and retracted else 1.0 for v in chain.variables])
    rod = np.array(
        [
            -1.0 if v.kind == "piston_offset" and retracted else float(v.kind in ("rod_length", "retracted_length"))
            for v in chain.variables
        ]
    )
    return columns, moves, rod


class StrokeRows:
    """The stroke rows of ``machine``'s stroke chains, the chain of index c driven by joint ``joints[c]``."""

    def __init__(self, machine: Machine, joints: tuple[int, ...]) -> None:
        self.machine = machine
        self.chains = chains_with_strokes(machine)
        self.joints = joints
        keys = tuple(machine.variable_keys)
        self.n_xi = len(keys)
        variables = machine.decision_variables
        self._columns = {c.name: [k for k, v in enumerate(variables) if v.chain == c.name] for c in self.chains}
        self._maps = {c.name: _variable_map(c, keys) for c in self.chains}
        self._chain_cache: dict[tuple[str, bytes], Chain] = {}
        self._partials_cache: dict[tuple[tuple[str, bytes], bytes], tuple[Array, Array]] = {}

    def chains_at(self, design: Any) -> list[tuple[tuple[str, bytes], Any]]:
        """(key, chain) of every stroke chain with ``design``'s values, cached by the chain's name and values."""
        values = np.asarray(design.as_array(), dtype=float)
        out = []
        for chain in self.chains:
            key = (chain.name, values[self._columns[chain.name]].tobytes())
            if key not in self._chain_cache:
                if len(self._chain_cache) > CACHE_SIZE:
                    self._chain_cache.clear()
                self._chain_cache[key] = designed_chain(self.machine, chain, values, bodies=False)
            out.append((key, self._chain_cache[key]))
        return out

    def margins(self, design: Any, q: Array) -> Array:
        """x, Lc - x, stroke - x per stroke chain [m] at joint samples q (K, n), (K, 3 m)."""
        cols = []
        for (_, chain), j in zip(self.chains_at(design), self.joints, strict=True):
            x = joint_to_stroke(self.machine, chain, q[:, j])
            act = chain.actuator
            cols += [x, float(act.rod_length) - x, act.stroke - x]
        return np.column_stack(cols)

    def partials(self, design: Any, q: Array) -> tuple[Array, Array]:
        """Exact partials of :meth:`margins` w.r.t. q (K, 3 m, n) and Xi (K, 3 m, n_xi)."""
        K, n = q.shape
        chains = self.chains_at(design)
        dq = np.zeros((K, 3 * len(chains), n))
        dxi = np.zeros((K, 3 * len(chains), self.n_xi))
        for c, ((key, chain), j) in enumerate(zip(chains, self.joints, strict=True)):
            at = (key, q[:, j].tobytes())
            if at not in self._partials_cache:
                if len(self._partials_cache) > CACHE_SIZE:
                    self._partials_cache.clear()
                self._partials_cache[at] = stroke_design_partials(self.machine, chain, q[:, j])
            ds_dq, dx_dv = self._partials_cache[at]
            r = 3 * c
            dq[:, r, j], dq[:, r + 1, j], dq[:, r + 2, j] = ds_dq, -ds_dq, -ds_dq
            columns, moves, rod = self._maps[chain.name]
            dx = dx_dv * moves  # (K, v)
            dxi[:, r, columns] = dx
            dxi[:, r + 1, columns] = rod - dx
            dxi[:, r + 2, columns] = -dx
        return dq, dxi

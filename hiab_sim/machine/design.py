"""Decision variables of a machine: their current values, and the machine built with new values.

Kinds (see :mod:`hiab_sim.machine.description`): ``hinge_distance`` moves a pivot along the line
from the chain's hinge through it (the seed's L); ``pivot_x``/``pivot_y`` set a pivot coordinate
in its link frame; ``piston_offset`` (Lc0), ``rod_length`` (Lc), ``retracted_length`` (x0 = Lc0 +
Lc, the rod length takes x0 - Lc0). Values in m.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Protocol, TypeVar

import numpy as np

from hiab_sim.checks import check_range
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.chains import Chain, DecisionVariable
from hiab_sim.machine.parts import vec3


class Designable(Protocol):
    """What this module needs of a :class:`~hiab_sim.machine.description.Machine` (no import circle)."""

    @property
    def chains(self) -> tuple[Chain, ...]:
        """The chains."""

    @property
    def decision_variables(self) -> tuple[DecisionVariable, ...]:
        """The declared decision variables."""

    @property
    def variable_keys(self) -> list[str]:
        """Their ``chain.name`` keys."""

    def chain(self, name: str) -> Chain:
        """The chain of this name."""

    def hinge_xy(self, chain: Chain, link: str) -> np.ndarray:
        """The chain's hinge in a link frame."""


MachineT = TypeVar("MachineT", bound=Designable)


def variable_value(machine: Designable, variable: DecisionVariable) -> float:
    """Current value of a decision variable [m]."""
    chain = machine.chain(variable.chain)
    act = chain.actuator
    if variable.kind in ("piston_offset", "rod_length", "retracted_length"):
        value = getattr(act, variable.kind)
        if value is None:
            raise InvalidInputError(variable.key, "None", "a direct actuator has no such length")
        return float(value)
    pivot = chain.pivot(str(variable.pivot))
    if variable.kind == "pivot_x":
        return pivot.position[0]
    if variable.kind == "pivot_y":
        return pivot.position[1]
    return float(np.linalg.norm(pivot.xy - machine.hinge_xy(chain, pivot.link)))


def with_design(machine: MachineT, values: Any, *, check_bounds: bool = True) -> MachineT:
    """The machine with its decision variables set to ``values`` (in ``machine.decision_variables`` order).

    Values outside the declared bounds raise :class:`InvalidInputError` unless ``check_bounds`` is
    False (e.g. finite differences at a bound). With ``body_scaling: slender`` the cylinder body
    scales with x0 and the rod body with Lc (:meth:`hiab_sim.machine.parts.RigidBody.scaled_slender`).
    The loop closure is not checked here (:func:`hiab_sim.machine.kinematics.closure.check_machine` does).
    """
    values = np.asarray(values, dtype=float).reshape(-1)
    variables = machine.decision_variables
    if values.shape != (len(variables),):
        raise InvalidInputError("design", f"{values.size} values", f"need {len(variables)}: {machine.variable_keys}")
    for v, value in zip(variables, values, strict=True):
        check_range(v.key, float(value), v.low if check_bounds else None, v.high if check_bounds else None, "m")
    return replace(machine, chains=tuple(designed_chain(machine, chain, values) for chain in machine.chains))  # type: ignore[type-var]


def designed_chain(machine: Designable, chain: Chain, values: np.ndarray, *, bodies: bool = True) -> Chain:
    """One chain of ``machine`` with its decision variables taken from ``values`` (all of them, in order).

    The chain :func:`with_design` builds, without building the machine around it: for geometry that
    reads one chain and the links (which no decision variable moves), e.g. the stroke rows. Values
    are not checked here. ``bodies=False`` keeps the actuator's bodies as they are (no slender
    scaling): the chain's geometry is the same, its masses and inertias are not the design's.
    """
    mine = [(v, float(x)) for v, x in zip(machine.decision_variables, values, strict=True) if v.chain == chain.name]
    return _chain_with(machine, chain, mine, bodies) if mine else chain


def _chain_with(
    machine: Designable, chain: Chain, assigned: list[tuple[DecisionVariable, float]], bodies: bool = True
) -> Chain:
    act = chain.actuator
    piston, rod = act.piston_offset, act.rod_length
    pivots = {p.role: p for p in chain.pivots}
    for v, value in assigned:
        if v.kind == "piston_offset":
            piston = value
        elif v.kind == "rod_length":
            rod = value
        elif v.kind != "retracted_length":
            p = pivots[str(v.pivot)]
            pos = np.asarray(p.position, dtype=float)
            if v.kind == "pivot_x":
                pos[0] = value
            elif v.kind == "pivot_y":
                pos[1] = value
            else:
                hinge = machine.hinge_xy(chain, p.link)
                pos[:2] = hinge + value * (p.xy - hinge) / np.linalg.norm(p.xy - hinge)
            pivots[p.role] = replace(p, position=vec3(pos))
    for v, value in assigned:  # after Lc0 is known
        if v.kind == "retracted_length" and piston is not None:
            rod = value - piston
    new = replace(act, piston_offset=piston, rod_length=rod)
    x0_old, x0_new = act.retracted_length, new.retracted_length
    if bodies and act.body_scaling == "slender" and x0_old is not None and x0_new is not None:
        if act.cylinder_body is not None:
            new = replace(new, cylinder_body=act.cylinder_body.scaled_slender(x0_new / x0_old))
        if act.rod_body is not None and rod is not None and act.rod_length is not None:
            new = replace(new, rod_body=act.rod_body.scaled_slender(rod / act.rod_length))
    return replace(chain, actuator=new, pivots=tuple(pivots[p.role] for p in chain.pivots))


@dataclass(frozen=True)
class MachineDesign:
    """A machine's decision-variable values (``names`` in order) [m or rad by kind]."""

    names: tuple[str, ...]
    values: tuple[float, ...]

    def as_array(self) -> np.ndarray:
        """The values, (n_xi,)."""
        return np.asarray(self.values, dtype=float)

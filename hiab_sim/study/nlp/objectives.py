"""Objectives of the NLP, each a value and a gradient w.r.t. per-sample q9 and Xi (see :mod:`.nlp`).

* :class:`SquaredPowerCost` (``costf2``, the seed's eq. ``costf2``, the default):
  f = 1/2 Dt sum_k (sum_i P_i(t_k))^2 [W^2 s], a rectangle sum over every sample of the squared
  summed EMLA electrical power P_i (:mod:`hiab_sim.emla`, never f v / eta). It is a
  squared-power integral, not an energy.
* :class:`BatteryEnergyCost` (``battery_energy``): the energy the battery delivers over the cycle
  through a DC bus shared by the drives (:func:`hiab_sim.emla.battery_energy`: inverter, bus,
  battery charge/discharge efficiencies; regeneration of one drive feeds the others first),
  trapezoid rule on the sample grid [J]. The solver sees the softplus-smoothed kinks (width
  ``battery.smoothing_power`` of the EMLA set, error <= :meth:`BatteryParams.smoothing_bound`);
  reports use the exact value (:mod:`hiab_sim.study.report.energy_section`). With the study's duty
  model (``state.duty``) it adds the rest's battery energy (the hold, :mod:`hiab_sim.emla.hold`).

With a duty model the drive powers P_i are those at the winding temperature (R_s(T),
:mod:`hiab_sim.emla.duty_energy`), and both objectives' gradients include the temperature's
dependence on every sample (the adjoint of the coupled winding model).

An objective is chosen by name with :func:`make_objective`; a new one is a class with ``name``,
``unit``, ``measured_by``, ``value(state)`` and ``gradient(state, partials)`` registered with
:func:`register_objective` (docs/extending.md). ``measured_by`` names the energy of
:data:`RESULT_ENERGIES` whose saving answers the objective (``hiab-sim compare`` reports that one),
or is None where no energy measures it (``costf2``, a squared power: the net electrical energy's
saving is reported, as its paper does).
"""

from __future__ import annotations

from typing import ClassVar, Protocol

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla import EmlaSet, battery_energy, electrical_power_partials, operating_point
from hiab_sim.emla.battery import rest_battery_energy
from hiab_sim.errors import InvalidInputError
from hiab_sim.study.nlp.interface import Objective, SamplePartials, SampleState


class EmlaObjective:
    """An objective of the EMLA set's drives over the sample grid: the set and the sample step Dt [s] it holds."""

    def __init__(self, emlas: EmlaSet, dt: float) -> None:
        self.emlas = emlas
        self.dt = dt


class SquaredPowerCost(EmlaObjective):
    """f = 1/2 Dt sum_k (sum_i P_i(t_k))^2 (seed eq. ``costf2``) [W^2 s].

    Args:
        emlas: the EMLA set whose electrical power P_i the state carries.
        dt: the sample step Dt [s].

    """

    name = "costf2"
    unit = "W^2 s"
    measured_by: ClassVar[str | None] = None  # a squared power, not an energy

    def value(self, state: SampleState) -> float:
        """1/2 Dt sum_k (sum_i P_i)^2 [W^2 s]."""
        total = state.power.sum(axis=1)
        return 0.5 * self.dt * float(np.sum(total**2))

    def gradient(self, state: SampleState, partials: SamplePartials) -> tuple[Array, Array]:
        """Dt (sum_i P_i) dP/d(f, v, a) chained through the inverse dynamics' partials."""
        total = state.power.sum(axis=1)
        return _chain(self.emlas, state, partials, self.dt * np.repeat(total[:, None], len(self.emlas), axis=1))


class BatteryEnergyCost(EmlaObjective):
    """E_bat = int P_bat dt over the sample grid (trapezoid), smooth kinks [J] (:mod:`hiab_sim.emla.battery`).

    Args:
        emlas: the EMLA set (its ``battery`` section gives the efficiencies and the smoothing).
        dt: the sample step Dt [s] (unused: the trapezoid weights come from the state's times).

    """

    name = "battery_energy"
    unit = "J"
    measured_by: ClassVar[str | None] = "battery_energy"

    def value(self, state: SampleState) -> float:
        """Smooth battery energy [J] of the cycle, plus the rest's (exact, it only draws) with a duty model."""
        cycle = battery_energy(state.joints.time, state.power, self.emlas.battery, smooth=True).energy
        return cycle + self._rest(state)

    def _rest(self, state: SampleState) -> float:
        """The rest's battery energy [J] with a duty model (the hold), else 0."""
        if state.duty is None:
            return 0.0
        return rest_battery_energy([d.rest_energy for d in state.duty], self.emlas.battery)[0]

    def exact(self, state: SampleState) -> float:
        """Exact battery energy [J]: the drives' exact electrical power, the kinks unsmoothed (as reports give it).

        With a duty model the drive powers are the state's hot ones (R_s(T)) with the battery's kinks
        unsmoothed, plus the rest's energy; the duty report (:mod:`hiab_sim.study.report.duty_section`)
        gives the fully exact split.
        """
        if state.duty is not None:
            return battery_energy(state.joints.time, state.power, self.emlas.battery).energy + self._rest(state)
        act = state.actuators
        power = np.column_stack(
            [
                operating_point(
                    p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i], exact=True
                ).electrical_power
                for i, p in enumerate(self.emlas)
            ]
        )
        return battery_energy(state.joints.time, power, self.emlas.battery).energy

    def gradient(self, state: SampleState, partials: SamplePartials) -> tuple[Array, Array]:
        """dE/dP_i (per sample and drive) chained through dP/d(f, v, a) and the inverse dynamics' partials."""
        dE_dP = battery_energy(state.joints.time, state.power, self.emlas.battery, smooth=True).gradient
        gain = 0.0 if state.duty is None else rest_battery_energy([0.0], self.emlas.battery)[1]
        return _chain(self.emlas, state, partials, dE_dP, gain)


def _chain(
    emlas: EmlaSet, state: SampleState, partials: SamplePartials, df_dP: Array, df_drest: float = 0.0
) -> tuple[Array, Array]:
    """(d/dq9 (K, 3 n), d/dXi (n_xi,)) of an objective from its partials w.r.t. each drive's power, df_dP (K, n).

    With a duty model (``state.duty``) the powers are the hot ones and ``df_drest`` [-] multiplies each
    drive's rest energy; the partials then carry the winding temperature's dependence on every sample.
    """
    act = state.actuators
    n = len(emlas)
    dY = np.zeros((len(state.power), 3 * n))  # w.r.t. Y = (f_0..f_n-1, v_0.., a_0..)
    for i, p in enumerate(emlas):
        if state.duty is not None:
            pf, pv, pa = state.duty[i].energy_partials(df_dP[:, i], df_drest)
            dY[:, i], dY[:, n + i], dY[:, 2 * n + i] = pf, pv, pa
            continue
        pf, pv, pa = electrical_power_partials(p, act.force[:, i], act.velocity[:, i], act.acceleration[:, i])
        dY[:, i], dY[:, n + i], dY[:, 2 * n + i] = df_dP[:, i] * pf, df_dP[:, i] * pv, df_dP[:, i] * pa
    return np.einsum("ky,kyq->kq", dY, partials.id_q), np.einsum("ky,kyx->x", dY, partials.id_xi)


#: The energies a result gives for every design that an objective's ``measured_by`` may name: the net
#: electrical energy at the drives' terminals (regeneration credited) and the energy the battery
#: delivers (through the inverters, the shared DC bus and the battery's efficiencies).
RESULT_ENERGIES = ("net_electrical_energy", "battery_energy")


class ObjectiveFactory(Protocol):
    """Builds an objective from (EMLA set, sample step Dt [s]): the objective's class.

    ``measured_by``: the energy of :data:`RESULT_ENERGIES` whose saving answers the objective, or
    None where no energy measures it (the net electrical energy's saving is then reported).
    """

    measured_by: str | None

    def __call__(self, emlas: EmlaSet, dt: float) -> Objective:
        """The objective on the EMLA set ``emlas`` with sample step ``dt`` [s]."""
        ...


#: The one registry of objectives, by the name a study gives (``objective:``); the study loader,
#: the NLP, co-design, the energy map, the Pareto front and the reports read it.
OBJECTIVES: dict[str, ObjectiveFactory] = {
    "costf2": SquaredPowerCost,
    "battery_energy": BatteryEnergyCost,
}


def register_objective(name: str, factory: ObjectiveFactory) -> None:
    """Make ``objective: <name>`` available to every study (``factory(emlas, dt)`` builds it).

    The factory declares ``measured_by`` (:class:`ObjectiveFactory`): None or one of :data:`RESULT_ENERGIES`.
    """
    if not name.isidentifier():
        raise InvalidInputError("objective name", name, "must be an identifier (letters, digits, _)")
    if name in OBJECTIVES:
        raise InvalidInputError("objective name", name, f"already registered; registered: {', '.join(OBJECTIVES)}")
    measured = getattr(factory, "measured_by", "(not declared)")
    if measured is not None and measured not in RESULT_ENERGIES:
        raise InvalidInputError(
            f"objective {name}: measured_by",
            measured,
            f"must be None (no energy measures it) or one of {', '.join(RESULT_ENERGIES)}",
        )
    OBJECTIVES[name] = factory


def unregister_objective(name: str) -> None:
    """Remove a registered objective (the built-in ones stay)."""
    if name in ("costf2", "battery_energy"):
        raise InvalidInputError("objective name", name, "a built-in objective cannot be removed")
    OBJECTIVES.pop(name, None)


def check_objective_name(name: object, field: str = "objective") -> str:
    """``name`` if it is a registered objective, else one line naming ``field`` and the allowed names."""
    if not isinstance(name, str) or name not in OBJECTIVES:
        raise InvalidInputError(field, name, f"must be one of {', '.join(OBJECTIVES)}")
    return name


def measured_by(name: str) -> str | None:
    """The energy of :data:`RESULT_ENERGIES` that measures the objective called ``name``.

    None where none does (``costf2``) or where no objective of that name is registered in this
    process (a result of an objective registered by another program).
    """
    factory = OBJECTIVES.get(name)
    return None if factory is None else factory.measured_by


def make_objective(name: str, emlas: EmlaSet, dt: float) -> Objective:
    """The objective called ``name`` (one of :data:`OBJECTIVES`)."""
    return OBJECTIVES[check_objective_name(name)](emlas, dt)


def exact_value(objective: Objective, state: SampleState) -> float:
    """The objective's exact value [its unit]: its ``exact(state)`` where it smooths for the solver, else its value."""
    exact = getattr(objective, "exact", None)
    return float(exact(state)) if callable(exact) else float(objective.value(state))


def costf2(emlas: EmlaSet, dt: float) -> SquaredPowerCost:
    """The squared-power integral of eq. ``costf2`` [W^2 s], reported for every objective."""
    return SquaredPowerCost(emlas, dt)

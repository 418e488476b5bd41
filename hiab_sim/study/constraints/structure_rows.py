"""Structural rows of the NLP: screw buckling, pin peak loads and the lowest natural frequency, per sample.

Each block is a :class:`~hiab_sim.study.nlp.interface.PerSampleBlock` (the same rows at every sample):

* :class:`BucklingRows` (``structure.buckling``): 1 - n f / P_cr >= 0 per actuator with screw data
  (:mod:`hiab_sim.structure.buckling`); exact partials of P_cr w.r.t. theta and Xi, chained with the
  inverse dynamics' partials of f (:class:`~hiab_sim.study.nlp.interface.SamplePartials`);
* :class:`PinLoadRows` (``structure.pin_load_limits``): 1 - |F_p| / F_max >= 0 per limited pin
  (:mod:`hiab_sim.structure.pin_loads`, the analytic path); partials by central differences of the
  vectorised pin forces (all samples perturbed together, as the ID partials are);
* :class:`NaturalFrequencyRows` (``structure.min_natural_frequency_Hz``): f_1 / f_min - 1 >= 0, the
  lowest locked-rotor frequency at the sample's pose with the payload held at the TCP
  (:mod:`hiab_sim.structure.natural_frequency`);
  partials w.r.t. the sample's positions and Xi by central differences.

:func:`structure_blocks` builds the blocks a study's ``structure`` section asks for, of a crane file
(:data:`CRANE_ROWS`) or of a machine file (:data:`~hiab_sim.study.constraints.machine_structure_rows.MACHINE_ROWS`);
the base classes hold what the two share (names, rows, relaxations).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane
from hiab_sim.emla import EmlaSet
from hiab_sim.results.design_values import crane_lengths
from hiab_sim.structure.buckling import buckled_actuators, buckling_samples, utilisation_partials
from hiab_sim.structure.natural_frequency import natural_frequencies
from hiab_sim.structure.pin_loads import pin_forces, pins
from hiab_sim.structure.settings import StructureSettings
from hiab_sim.study.constraints.differenced_rows import DifferencedRows
from hiab_sim.study.nlp.interface import PerSampleBlock, Relaxation, SamplePartials, SampleRows, SampleState


def _per_sample_force(tcp_force: Array | None, samples: int) -> Array | None:
    """The TCP force [N] broadcast to (K, 3), or None without one."""
    return None if tcp_force is None else np.broadcast_to(np.asarray(tcp_force, float), (samples, 3))


class BucklingRowsBase(PerSampleBlock):
    """1 - n f / P_cr per actuator with screw data and sample: the name and relaxation of a crane's and a machine's."""

    def __init__(self, times: Array, model: Any, safety_factor: float) -> None:
        self.name = "structure.buckling"
        self.times = times
        self.model = model
        self.safety_factor = safety_factor

    def relaxation(self, values: Array) -> Relaxation:
        """Per % of the buckling load: 1 - n f / (1.01 P_cr) - (1 - n f / P_cr) = (1 - g)(1 - 1 / 1.01)."""
        g = np.asarray(values, dtype=float)
        return Relaxation(("%",) * len(g), (1.0 - g) * (1.0 - 1.0 / 1.01))


class PinLoadRowsBase(DifferencedRows):
    """1 - |F_p| / F_max per limited pin and sample; a subclass gives the pins' force magnitudes."""

    def __init__(
        self, times: Array, model: Any, limits: tuple[tuple[str, float], ...], tcp_force: Array | None, step: float
    ) -> None:
        self.name = "structure.pin_load"
        self.times = times
        self.model = model
        self.limits = limits
        self.limit = np.array([value for _, value in limits])
        self.tcp_force = _per_sample_force(tcp_force, len(times))
        self.step = step
        self.sample_rows = tuple(f"{name} |F| <= {value:.6g} N" for name, value in limits)

    def _magnitudes(self, design: Any, position: Array, velocity: Array, acceleration: Array) -> Array:
        """|F_p| [N] (K, limited pins) of the limited pins, in the order of ``limits``."""
        raise NotImplementedError

    def _rows(self, design: Any, position: Array, velocity: Array, acceleration: Array) -> Array:
        return 1.0 - self._magnitudes(design, position, velocity, acceleration) / self.limit

    def relaxation(self, values: Array) -> Relaxation:
        """Per kN of a pin's rating: d(1 - |F| / F_max)/dF_max = (1 - g) / F_max, times 1e3 N (per pin)."""
        g = np.asarray(values, dtype=float)
        return Relaxation(("kN",) * len(g), (1.0 - g) * 1e3 / np.tile(self.limit, len(g) // len(self.limit)))


class FrequencyRowsBase(DifferencedRows):
    """f_1(q_k, Xi) / f_min - 1 per sample; a subclass gives the lowest locked-rotor frequency at the pose."""

    uses_rates = False

    def __init__(
        self,
        times: Array,
        model: Any,
        emlas: EmlaSet,
        minimum_Hz: float,
        tcp_force: Array | None,
        step: float,
        payload_kg: float = 0.0,
    ) -> None:
        self.name = "structure.natural_frequency"
        self.times = times
        self.model = model
        self.emlas = emlas
        self.minimum = minimum_Hz
        self.tcp_force = _per_sample_force(tcp_force, len(times))
        self.step = step
        self.payload_kg = payload_kg
        self.sample_rows = (f"lowest frequency >= {minimum_Hz:.6g} Hz",)

    def _lowest_Hz(self, design: Any, position: Array) -> Array:
        """f_1 [Hz] (K,) at each sample's pose, the payload held at the TCP."""
        raise NotImplementedError

    def _rows(self, design: Any, position: Array, velocity: Array, acceleration: Array) -> Array:
        return (self._lowest_Hz(design, position) / self.minimum - 1.0)[:, None]

    def relaxation(self, values: Array) -> Relaxation:
        """Per Hz of the minimum lowered: d(f / f_min - 1)/d(-f_min) = (1 + g) / f_min."""
        g = np.asarray(values, dtype=float)
        return Relaxation(("Hz",) * len(g), (1.0 + g) / self.minimum)


@dataclass(frozen=True)
class StructureRowKinds:
    """The three structural blocks of one kind of model (a crane file's or a machine file's).

    ``buckles(model, emlas)``: whether any actuator has screw data to buckle; :func:`structure_blocks` builds them.
    """

    buckling: Callable[[Array, Any, EmlaSet, float], PerSampleBlock]
    buckles: Callable[[Any, EmlaSet], bool]
    pin_load: Callable[[Array, Any, tuple[tuple[str, float], ...], Array | None, float], PerSampleBlock]
    frequency: Callable[[Array, Any, EmlaSet, float, Array | None, float, float], PerSampleBlock]


class BucklingRows(BucklingRowsBase):
    """1 - n f / P_cr per actuator with screw data and sample (:mod:`hiab_sim.structure.buckling`)."""

    model: Crane

    def __init__(self, times: Array, crane: Crane, emlas: EmlaSet, safety_factor: float) -> None:
        super().__init__(times, crane, safety_factor)
        self.emlas = emlas
        self.sample_rows = tuple(f"{a.name} push <= P_cr / n" for a, _ in buckled_actuators(crane, emlas))

    def values(self, state: SampleState) -> Array:
        """1 - u per sample, sample-major (K * r,)."""
        u = buckling_samples(
            self.model,
            self.emlas,
            crane_lengths(state.lengths),
            state.joints.position,
            state.actuators.force,
            self.safety_factor,
        ).utilisation
        return (1.0 - u).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """-du/dq9 and -du/dXi (exact P_cr partials, the ID's force partials)."""
        du_dq, du_dxi = utilisation_partials(
            self.model,
            self.emlas,
            crane_lengths(state.lengths),
            state.joints.position,
            state.actuators.force,
            partials.id_q[:, 0:3, :],
            partials.id_xi[:, 0:3, :],
            self.safety_factor,
        )
        return SampleRows(-du_dq, -du_dxi)


class PinLoadRows(PinLoadRowsBase):
    """1 - |F_p| / F_max per limited pin and sample (analytic pin forces)."""

    model: Crane

    def __init__(
        self, times: Array, crane: Crane, limits: tuple[tuple[str, float], ...], tcp_force: Array | None, step: float
    ) -> None:
        super().__init__(times, crane, limits, tcp_force, step)
        names = [pin.name for pin in pins(crane)]
        self.index = np.array([names.index(name) for name, _ in limits])

    def _magnitudes(self, design: Any, position: Array, velocity: Array, acceleration: Array) -> Array:
        loads = pin_forces(self.model, crane_lengths(design), position, velocity, acceleration, self.tcp_force)
        return loads.magnitude[:, self.index]


class NaturalFrequencyRows(FrequencyRowsBase):
    """f_1(q_k, Xi) / f_min - 1 per sample: the lowest locked-rotor frequency at the sample's pose."""

    model: Crane

    def _lowest_Hz(self, design: Any, position: Array) -> Array:
        modes = natural_frequencies(
            self.model, self.emlas, crane_lengths(design), position, self.tcp_force, payload_kg=self.payload_kg
        )
        return modes.lowest_Hz


#: The crane file's structural blocks (closed-form kinematics and analytic inverse dynamics).
CRANE_ROWS = StructureRowKinds(
    BucklingRows, lambda crane, emlas: bool(buckled_actuators(crane, emlas)), PinLoadRows, NaturalFrequencyRows
)


def structure_blocks(
    settings: StructureSettings,
    times: Array,
    model: Any,
    emlas: EmlaSet,
    tcp_force: Array | None,
    step: float,
    payload_kg: float = 0.0,
    kinds: StructureRowKinds = CRANE_ROWS,
) -> list[PerSampleBlock]:
    """The structural blocks the study's ``structure`` section asks for (none by default).

    ``model``: the crane (``kinds`` :data:`CRANE_ROWS`) or the machine model (``kinds``
    :data:`~hiab_sim.study.constraints.machine_structure_rows.MACHINE_ROWS`); ``tcp_force``: the task's TCP force
    per sample [N]; ``payload_kg``: its payload, held at the TCP.
    """
    out: list[PerSampleBlock] = []
    if settings.buckling and kinds.buckles(model, emlas):
        out.append(kinds.buckling(times, model, emlas, settings.buckling_safety_factor))
    if settings.pin_load_limits_N:
        out.append(kinds.pin_load(times, model, settings.pin_load_limits_N, tcp_force, step))
    if settings.min_natural_frequency_Hz is not None:
        floor = settings.min_natural_frequency_Hz
        out.append(kinds.frequency(times, model, emlas, floor, tcp_force, step, payload_kg))
    return out

"""One design's structural state along its motion, and the initial-vs-optimal section of a result.

:func:`design_structure` evaluates, for one design (link lengths, joint samples of its trajectory,
the actuator forces of the inverse dynamics, the TCP force):

* every pin's peak force, its fatigue-relevant range (largest change of the force vector) and its
  magnitude range (:mod:`hiab_sim.structure.pin_loads`, analytic path);
* every screw's largest buckling utilisation n f / P_cr, its shortest critical load and longest
  column (:mod:`hiab_sim.structure.buckling`), with the study's safety factor;
* the lowest locked-rotor natural frequency over the trajectory's samples and over a grid of the
  design's working range (:mod:`hiab_sim.structure.natural_frequency`), when every actuator has
  drive-stiffness data.

The dataclasses are the ``structure`` section of ``result.json`` (SI units, names carry them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla.config import EmlaSet
from hiab_sim.structure.buckling import DEFAULT_SAFETY_FACTOR, BucklingSamples, buckling_samples
from hiab_sim.structure.natural_frequency import natural_frequencies, working_range_poses
from hiab_sim.structure.pin_loads import PinLoads, analytic_pin_loads

Array = NDArray[np.float64]

#: Grid of the working range for the frequency map: per chain joint, then the direct joint.
WORKING_GRID = (9, 9, 3)


@dataclass(frozen=True)
class PinSummary:
    """One pin over the motion [N]; ``peak_direction_rad``: the peak force's angle in the bracket frame."""

    peak_N: float
    vector_range_N: float
    magnitude_range_N: float
    peak_direction_rad: float


@dataclass(frozen=True)
class BucklingSummary:
    """One screw over the motion: largest n f / P_cr [-], largest push [N], smallest P_cr [N], longest column [m]."""

    max_utilisation: float
    peak_push_N: float
    min_critical_load_N: float
    max_column_length_m: float


@dataclass(frozen=True)
class DesignStructure:
    """Pins, screws and the lowest natural frequency of one design (None where data are missing)."""

    pins: dict[str, PinSummary]
    most_loaded_pin: str
    buckling: dict[str, BucklingSummary]
    buckling_safety_factor: float
    lowest_frequency_trajectory_Hz: float | None
    lowest_frequency_working_range_Hz: float | None


@dataclass(frozen=True)
class StructureSummary:
    """The ``structure`` section of a result: the initial and the optimal design on the fine grid."""

    initial: DesignStructure
    optimal: DesignStructure
    note: str = (
        "pin forces of the member on its bracket (analytic Newton-Euler, equal to MuJoCo's to round-off); "
        "buckling utilisation n f / P_cr (Euler / Johnson, <= 1 holds); locked-rotor natural frequencies"
    )


def has_stiffness(emlas: EmlaSet) -> bool:
    """True when every actuator has screw and drive-stiffness data (the frequencies need all)."""
    return all(p.screw is not None and p.stiffness is not None for p in emlas)


def pin_summaries(loads: PinLoads) -> dict[str, PinSummary]:
    """Each pin's peak, vector and magnitude ranges [N] and the peak's direction in its bracket frame [rad]."""
    peak_index = np.argmax(loads.magnitude, axis=0)
    direction = loads.direction[peak_index, np.arange(len(loads.pins))]
    peak, vector, magnitude = loads.peak(), loads.vector_range(), loads.magnitude_range()
    return {
        pin.name: PinSummary(peak[pin.name], vector[pin.name], magnitude[pin.name], float(direction[k]))
        for k, pin in enumerate(loads.pins)
    }


def buckling_summaries(b: BucklingSamples) -> dict[str, BucklingSummary]:
    """Each screw's largest utilisation [-], largest push [N], smallest P_cr [N] and longest column [m]."""
    return {
        name: BucklingSummary(
            float(np.max(b.utilisation[:, k])),
            float(max(0.0, np.max(b.force[:, k]))),
            float(np.min(b.critical_load[:, k])),
            float(np.max(b.length[:, k])),
        )
        for k, name in enumerate(b.names)
    }


def design_structure(
    crane: Crane,
    emlas: EmlaSet,
    lengths: LinkLengths,
    joints: JointSamples,
    force: ArrayLike,
    tcp_force: ArrayLike | None = None,
    safety_factor: float = DEFAULT_SAFETY_FACTOR,
    payload_kg: float = 0.0,
) -> DesignStructure:
    """Structural summary of one design (module docstring); ``force`` (T, n_a) [N] from the inverse dynamics.

    The working-range grid spans the chains' ``joint_range`` of ``crane`` (a study's problem narrows
    them to the range its design serves) and carries the largest TCP force of the samples as a constant
    load. ``payload_kg``: the payload's mass, held rigidly at the TCP for the frequencies (its weight is
    in ``tcp_force``).
    """
    loads = analytic_pin_loads(crane, lengths, joints, tcp_force)
    pins = pin_summaries(loads)
    buckling = buckling_summaries(buckling_samples(crane, emlas, lengths, joints.position, force, safety_factor))
    trajectory_Hz = grid_Hz = None
    if has_stiffness(emlas):
        external = None if tcp_force is None else np.asarray(tcp_force, dtype=float)
        on_path = natural_frequencies(crane, emlas, lengths, joints.position, external, payload_kg=payload_kg)
        trajectory_Hz = float(np.min(on_path.lowest_Hz))
        poses = working_range_poses(crane, WORKING_GRID)
        grid = natural_frequencies(crane, emlas, lengths, poses, largest(external), payload_kg=payload_kg)
        grid_Hz = float(np.min(grid.lowest_Hz))
    return DesignStructure(
        pins=pins,
        most_loaded_pin=loads.most_loaded()[0],
        buckling=buckling,
        buckling_safety_factor=safety_factor,
        lowest_frequency_trajectory_Hz=trajectory_Hz,
        lowest_frequency_working_range_Hz=grid_Hz,
    )


def largest(tcp_force: Array | None) -> Array | None:
    """A constant TCP force for the working-range grid: the force itself, or the largest of its samples [N]."""
    if tcp_force is None or tcp_force.ndim == 1:
        return tcp_force
    return np.asarray(tcp_force[int(np.argmax(np.linalg.norm(tcp_force, axis=1)))])

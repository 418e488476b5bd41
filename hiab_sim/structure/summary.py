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

The dataclasses are the ``structure`` section of ``result.json`` (SI units, names carry them). A
duty mix's section is the envelope over its tasks (:func:`structure_envelope`): each task loads the
structure with its own motion and payload, and the design must hold all of them, so each value is
the worst over the tasks and :class:`TaskEnvelope` names the task that sets it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla.config import EmlaSet
from hiab_sim.errors import InvalidInputError
from hiab_sim.results.codec import optional
from hiab_sim.structure.buckling import DEFAULT_SAFETY_FACTOR, BucklingSamples, buckling_samples
from hiab_sim.structure.natural_frequency import natural_frequencies, working_range_poses
from hiab_sim.structure.pin_loads import PinLoads, analytic_pin_loads

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
class TaskEnvelope:
    """Which task of a duty mix sets each value of a design's envelope (:func:`structure_envelope`).

    Attributes:
        tasks: The mix's task names, in the study's order.
        pin_peak_task: Per pin, the task whose motion gives its peak force.
        buckling_task: Per screw, the task whose motion gives its largest utilisation n f / P_cr.
        smallest_buckling_margin: 1 - max n f / P_cr over every screw and task [-] (>= 0 holds), or
            None without screw data.
        smallest_buckling_margin_screw: The screw of that margin, or None.
        smallest_buckling_margin_task: The task of that margin, or None.
        lowest_frequency_trajectory_task: The task of the lowest frequency on its motion, or None
            without drive-stiffness data.
        lowest_frequency_working_range_task: The task of the lowest frequency over the working range
            (each task's grid carries its own largest TCP force), or None.

    """

    tasks: tuple[str, ...]
    pin_peak_task: dict[str, str]
    buckling_task: dict[str, str]
    smallest_buckling_margin: float | None
    smallest_buckling_margin_screw: str | None
    smallest_buckling_margin_task: str | None
    lowest_frequency_trajectory_task: str | None
    lowest_frequency_working_range_task: str | None


@dataclass(frozen=True)
class DesignStructure:
    """Pins, screws and the lowest natural frequency of one design (None where data are missing).

    ``envelope``: a duty mix's design only, the tasks that set its values (module docstring).
    """

    pins: dict[str, PinSummary]
    most_loaded_pin: str
    buckling: dict[str, BucklingSummary]
    buckling_safety_factor: float
    lowest_frequency_trajectory_Hz: float | None
    lowest_frequency_working_range_Hz: float | None
    envelope: TaskEnvelope | None = optional()


@dataclass(frozen=True)
class StructureSummary:
    """The ``structure`` section of a result: the initial and the optimal design on the fine grid."""

    initial: DesignStructure
    optimal: DesignStructure
    note: str = (
        "pin forces of the member on its bracket (analytic Newton-Euler, equal to MuJoCo's to round-off); "
        "buckling utilisation n f / P_cr (Euler / Johnson, <= 1 holds); locked-rotor natural frequencies"
    )


#: The note of a duty mix's section: what its envelope takes of the tasks.
MIX_NOTE = (
    StructureSummary.note + "; a duty mix: the envelope over its tasks, each pin's peak and range, each screw's "
    "utilisation and push the largest and its P_cr the smallest, the frequencies the lowest over the tasks "
    "(ranges within one task's cycle), envelope naming the task that sets each"
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
    buckling = buckling_samples(crane, emlas, lengths, joints.position, force, safety_factor)
    on_path = grid = None
    if has_stiffness(emlas):
        external = None if tcp_force is None else np.asarray(tcp_force, dtype=float)
        on_path = natural_frequencies(crane, emlas, lengths, joints.position, external, payload_kg=payload_kg).lowest_Hz
        poses = working_range_poses(crane, WORKING_GRID)
        grid = natural_frequencies(crane, emlas, lengths, poses, largest(external), payload_kg=payload_kg).lowest_Hz
    return summarise(loads, buckling, safety_factor, on_path, grid)


def summarise(
    loads: PinLoads, buckling: BucklingSamples, safety_factor: float, on_path_Hz: Array | None, grid_Hz: Array | None
) -> DesignStructure:
    """A design's summary from its pin loads, buckling samples and lowest frequencies [Hz] (None: no stiffness data).

    ``on_path_Hz``: f_1 at each sample of the motion; ``grid_Hz``: f_1 at each pose of the working-range grid.
    """
    return DesignStructure(
        pins=pin_summaries(loads),
        most_loaded_pin=loads.most_loaded()[0],
        buckling=buckling_summaries(buckling),
        buckling_safety_factor=safety_factor,
        lowest_frequency_trajectory_Hz=None if on_path_Hz is None else float(np.min(on_path_Hz)),
        lowest_frequency_working_range_Hz=None if grid_Hz is None else float(np.min(grid_Hz)),
    )


def largest(tcp_force: Array | None) -> Array | None:
    """A constant TCP force for the working-range grid: the force itself, or the largest of its samples [N]."""
    if tcp_force is None or tcp_force.ndim == 1:
        return tcp_force
    return np.asarray(tcp_force[int(np.argmax(np.linalg.norm(tcp_force, axis=1)))])


def _worst(values: Sequence[float | None], largest: bool) -> tuple[float | None, int | None]:
    """The largest (or smallest) value and its first index; (None, None) where any value is missing."""
    if any(v is None for v in values):
        return None, None
    numbers = np.asarray(values, dtype=float)
    k = int(np.argmax(numbers) if largest else np.argmin(numbers))
    return float(numbers[k]), k


def structure_envelope(sections: Sequence[DesignStructure], tasks: Sequence[str]) -> DesignStructure:
    """One design's structure over every task of a duty mix (module docstring), the tasks in study order.

    Per pin the largest peak (its direction that task's), vector and magnitude range; per screw the
    largest utilisation and push, the smallest P_cr and the longest column; the lowest frequencies.
    Ties go to the first task. Raises :class:`InvalidInputError` unless there is one section per
    task, all of the same pins and screws.
    """
    if not sections or len(sections) != len(tasks):
        raise InvalidInputError("sections", len(sections), f"must be one per task ({len(tasks)}), at least one")
    first = sections[0]
    for name, section in zip(tasks, sections, strict=True):
        if set(section.pins) != set(first.pins) or set(section.buckling) != set(first.buckling):
            raise InvalidInputError(f"sections.{name}", sorted(section.pins), "must have the first task's pins, screws")
    pins: dict[str, PinSummary] = {}
    pin_task: dict[str, str] = {}
    for pin in first.pins:
        own = [s.pins[pin] for s in sections]
        _, k = _worst([p.peak_N for p in own], largest=True)
        assert k is not None
        pins[pin] = PinSummary(
            own[k].peak_N,
            max(p.vector_range_N for p in own),
            max(p.magnitude_range_N for p in own),
            own[k].peak_direction_rad,
        )
        pin_task[pin] = tasks[k]
    buckling: dict[str, BucklingSummary] = {}
    screw_task: dict[str, str] = {}
    for screw in first.buckling:
        own_b = [s.buckling[screw] for s in sections]
        u, k = _worst([b.max_utilisation for b in own_b], largest=True)
        assert u is not None and k is not None
        buckling[screw] = BucklingSummary(
            u,
            max(b.peak_push_N for b in own_b),
            min(b.min_critical_load_N for b in own_b),
            max(b.max_column_length_m for b in own_b),
        )
        screw_task[screw] = tasks[k]
    margin: float | None = None
    weakest = margin_task = None
    if buckling:
        weakest = max(buckling, key=lambda name: buckling[name].max_utilisation)
        margin, margin_task = 1.0 - buckling[weakest].max_utilisation, screw_task[weakest]
    on_path, k_path = _worst([s.lowest_frequency_trajectory_Hz for s in sections], largest=False)
    grid, k_grid = _worst([s.lowest_frequency_working_range_Hz for s in sections], largest=False)
    return DesignStructure(
        pins=pins,
        most_loaded_pin=max(pins, key=lambda name: pins[name].peak_N),
        buckling=buckling,
        buckling_safety_factor=first.buckling_safety_factor,
        lowest_frequency_trajectory_Hz=on_path,
        lowest_frequency_working_range_Hz=grid,
        envelope=TaskEnvelope(
            tasks=tuple(tasks),
            pin_peak_task=pin_task,
            buckling_task=screw_task,
            smallest_buckling_margin=margin,
            smallest_buckling_margin_screw=weakest,
            smallest_buckling_margin_task=margin_task,
            lowest_frequency_trajectory_task=None if k_path is None else tasks[k_path],
            lowest_frequency_working_range_task=None if k_grid is None else tasks[k_grid],
        ),
    )


def mix_structure(sections: Sequence[StructureSummary], tasks: Sequence[str]) -> StructureSummary:
    """A duty mix's ``structure`` section: the envelope of the initial and of the optimal design over its tasks."""
    return StructureSummary(
        initial=structure_envelope([s.initial for s in sections], tasks),
        optimal=structure_envelope([s.optimal for s in sections], tasks),
        note=MIX_NOTE,
    )

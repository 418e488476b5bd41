"""The cascade's design for one plan: the crane's inertia at the slides, the frequencies to stay below, the check.

For a design's plan (:class:`~hiab_sim.env.plan.DesignPlan`) on a plant:

* the load mass of each slide along the plan, m_L,a = (J_x^-T M J_x^-1)_aa, the diagonal of the
  slide-space mass matrix (M the joint-space mass matrix with the payload at the TCP, J_x = dx/dq,
  :func:`hiab_sim.structure.natural_frequency.mass_matrix`): the kinetic energy m_L,a v_a^2 / 2 of
  the crane when slide a moves at v_a and the other slides are held by their loops; the velocity
  loop acts on J_m k^2 + M_sm + m_L,a (:mod:`hiab_sim.control.cascade`);
* f_1, the structure's lowest natural frequency over the plan's samples (locked rotor, the EMLA
  file's drive stiffness, the payload's weight and inertia;
  :func:`hiab_sim.structure.natural_frequency.natural_frequencies`), when every EMLA has the data;
* f_lock, the lowest locked-rod frequency sqrt(k_s / m_m) of a compliant plant's drive trains;
* the gains of :meth:`~hiab_sim.control.cascade.CascadeGains.design` and the check
  ``bandwidth_margin`` = 1 - f_v / (f_1 / 3) (>= 0 holds,
  :func:`~hiab_sim.structure.natural_frequency.bandwidth_margin`).

The frequencies are those of the planned crane, which is all the controller's designer knows (a
mismatch of the plant changes the simulated crane, not the design).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.control.cascade import DESIGN_RATIO, CascadeGains
from hiab_sim.env.plan import DesignPlan
from hiab_sim.env.plant.config import Plant
from hiab_sim.env.plant.drivetrain import drive_train_stiffness, locked_rod_frequency_Hz
from hiab_sim.env.reference import PlannedMotion
from hiab_sim.structure.natural_frequency import (
    MAX_BANDWIDTH_RATIO,
    bandwidth_margin,
    mass_matrix,
    natural_frequencies,
)
from hiab_sim.structure.summary import has_stiffness


@dataclass(frozen=True)
class LoopDesign:
    """The controller's design for one plan (module docstring).

    Attributes:
        gains: Loop bandwidths [rad/s].
        load_mass: m_L per slide at the planned motion's samples, (N, 3) [kg].
        stiffness: k_s per drive of a compliant plant [N/m], or None (rigid).
        lowest_resonance_hz: f_lock of a compliant plant [Hz], or None.
        first_natural_frequency_Hz: f_1 over the plan [Hz], or None (no drive-stiffness data).

    """

    gains: CascadeGains
    load_mass: Array
    stiffness: Array | None
    lowest_resonance_hz: float | None
    first_natural_frequency_Hz: float | None

    def check(self) -> dict[str, object]:
        """The bandwidth check of ``simulation.json``: f_v, f_1, their ratio and the margin, with their definition."""
        f_v = self.gains.velocity_Hz
        f_1 = self.first_natural_frequency_Hz
        return {
            "velocity_loop_bandwidth_Hz": f_v,
            "first_natural_frequency_Hz": f_1,
            "bandwidth_ratio": None if f_1 is None else f_v / f_1,
            "bandwidth_margin": None if f_1 is None else bandwidth_margin(f_v, f_1),
            "max_bandwidth_ratio": MAX_BANDWIDTH_RATIO,
            "design_ratio": DESIGN_RATIO,
            "lowest_drive_train_resonance_Hz": self.lowest_resonance_hz,
            "definition": (
                "bandwidth_margin = 1 - f_v / (f_1 / 3), >= 0 holds: the velocity loop's bandwidth f_v (the "
                "crossover on the reflected rotor plus the mechanism's mass at each slide) at most a third of the "
                "structure's lowest locked-rotor natural frequency f_1 over the plan's samples"
            ),
        }


def slide_load_mass(plan: DesignPlan, motion: PlannedMotion) -> Array:
    """m_L per slide (N, 3) [kg] at the motion's samples, from the plan's fine grid (module docstring)."""
    M, jx = mass_matrix(plan.crane, plan.lengths, plan.position, plan.payload)
    inverse = np.linalg.inv(jx)
    slide = np.einsum("tia,tij,tjb->tab", inverse, M, inverse)
    diagonal = np.diagonal(slide, axis1=1, axis2=2)
    grid = plan.time - plan.time[0]
    return np.stack([np.interp(motion.time, grid, diagonal[:, a]) for a in range(diagonal.shape[1])], axis=1)


def first_natural_frequency(plan: DesignPlan) -> float | None:
    """f_1 [Hz]: the structure's lowest natural frequency over the plan's samples, or None without the data."""
    if not has_stiffness(plan.emlas):
        return None
    modes = natural_frequencies(
        plan.crane, plan.emlas, plan.lengths, plan.position, plan.id_tcp_force(), payload_kg=plan.payload
    )
    return float(np.min(modes.lowest_Hz))


def design_loop(plan: DesignPlan, motion: PlannedMotion, plant: Plant | None) -> LoopDesign:
    """The design-rule gains and their check for a plan on a plant (module docstring)."""
    stiffness = lowest = None
    if plant is not None and plant.drive_train.enabled:
        stiffness = drive_train_stiffness(plan.emlas, motion.stroke)
        masses = np.array([p.motor.rotor_inertia * p.transmission_ratio**2 + p.screw_moving_mass for p in plan.emlas])
        lowest = float(locked_rod_frequency_Hz(stiffness, masses).min())
    first = first_natural_frequency(plan)
    return LoopDesign(CascadeGains.design(lowest, first), slide_load_mass(plan, motion), stiffness, lowest, first)

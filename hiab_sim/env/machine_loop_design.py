"""The machine closed loop's cascade design: the crane's rules with the machine's lowest structural frequency.

For a machine file's plan (:class:`~hiab_sim.env.machine_plan.MachinePlan`) the frequency the
velocity loop must stay below is the crane's f_1 (:mod:`hiab_sim.env.loop_design`) written for the
machine's description:

* f_1 = min over the plan's fine-grid samples of the lowest locked-rotor natural frequency
  (:func:`hiab_sim.structure.machine_modes.machine_natural_frequencies` on the Newton-Euler path:
  the EMLA file's drive stiffness, the plan's TCP force F(t) as the static load of the geometric
  stiffness, the study's payload held rigidly at the TCP), the value the result's ``structure``
  section reports as ``lowest_frequency_trajectory_Hz``; None when an EMLA lacks ``screw`` or
  ``drive_stiffness`` data;
* the gains of :meth:`~hiab_sim.control.cascade.CascadeGains.design`: w_v / 2 pi =
  min(8 Hz, f_lock / 2, 0.3 f_1), the crane's rule (``DESIGN_RATIO`` = 0.3), unless gains are given;
* the check of :meth:`~hiab_sim.env.loop_design.LoopDesign.check`: bandwidth_margin =
  1 - f_v / (f_1 / 3) >= 0 holds (:func:`~hiab_sim.structure.natural_frequency.bandwidth_margin`).
  Designed gains pass it by construction (margin 0.1); given gains, or a drive train softer than
  the one the gains were designed for, can fail it, and ``hiab-sim simulate`` says so in one line
  (:func:`hiab_sim.cli.simulate_summary.bandwidth_line`).

As on the crane, the frequencies are those of the planned machine, all the controller's designer knows.
"""

from __future__ import annotations

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.control.cascade import CascadeGains
from hiab_sim.env.loop_design import LoopDesign
from hiab_sim.env.machine_plan import MachinePlan
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.structure.machine_modes import machine_natural_frequencies
from hiab_sim.structure.summary import has_stiffness


def machine_first_natural_frequency(plan: MachinePlan) -> float | None:
    """f_1 [Hz]: the machine's lowest locked-rotor frequency over the plan's samples, or None without the data."""
    if not has_stiffness(plan.emlas):
        return None
    inverse = make_machine_dynamics(plan.machine, None, "newton_euler")
    modes = machine_natural_frequencies(
        plan.machine,
        inverse,
        plan.emlas,
        plan.position,
        plan.tcp_force[:, :2],
        plan.payload_kg,
        tracked=plan.tracked,
    )
    return float(np.min(modes.lowest_Hz))


def machine_loop_design(
    plan: MachinePlan,
    load_mass: Array,
    gains: CascadeGains | None = None,
    stiffness: Array | None = None,
    lowest_resonance_hz: float | None = None,
) -> LoopDesign:
    """The design-rule gains (or ``gains``) and their check against the machine's f_1 (module docstring).

    ``load_mass``: m_L per chain at the motion's samples (N, A) [kg]; ``stiffness`` and
    ``lowest_resonance_hz``: a compliant plant's k_s [N/m] and f_lock [Hz] (None: rigid).
    """
    first = machine_first_natural_frequency(plan)
    chosen = gains or CascadeGains.design(lowest_resonance_hz, first)
    return LoopDesign(chosen, load_mass, stiffness, lowest_resonance_hz, first)

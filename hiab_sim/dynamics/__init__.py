"""Inverse dynamics of the crane: joint samples in, actuator forces and velocities out (eq. dynamics).

Two independent paths compute the same quantities and are cross-validated (``hiab-sim validate``):
:mod:`hiab_sim.dynamics.mujoco_id` (MuJoCo's ``mj_inverse`` on the MJCF model) and
:mod:`hiab_sim.dynamics.analytic_id` (closed-chain trigonometry and screw-theory Newton-Euler).
Both satisfy :class:`~hiab_sim.dynamics.interface.InverseDynamics`; pick one by name with
:func:`~hiab_sim.dynamics.interface.make_inverse_dynamics`. Shared input checks live in
:mod:`hiab_sim.dynamics.checks`, the sample types in :mod:`hiab_sim.dynamics.samples`.
"""

from hiab_sim.dynamics.interface import ID_PATHS, InverseDynamics, inverse_dynamics, make_inverse_dynamics
from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples

__all__ = [
    "ID_PATHS",
    "ActuatorSamples",
    "InverseDynamics",
    "JointSamples",
    "inverse_dynamics",
    "make_inverse_dynamics",
]

"""Inverse dynamics of the crane: joint samples in, actuator forces and velocities out (eq. dynamics).

Two independent paths compute the same quantities and are cross-validated (``hiab-sim validate``):
:mod:`hiab_sim.dynamics.mujoco_id` (MuJoCo's ``mj_inverse`` on the MJCF model) and
:mod:`hiab_sim.dynamics.analytic_id` (closed-chain trigonometry and screw-theory Newton-Euler).
"""

from hiab_sim.dynamics.samples import ActuatorSamples, JointSamples, inverse_dynamics

__all__ = ["ActuatorSamples", "JointSamples", "inverse_dynamics"]

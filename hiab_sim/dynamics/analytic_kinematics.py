"""Loop kinematics and link twists of the crane for the analytic inverse dynamics, numpy only.

From samples of the independent joints (theta1, theta2, xt2) and a link-length set, this module
solves both closed chains with :mod:`hiab_sim.crane.mechanism` (seed eqs. qus, thetas, dq__,
k1_3, 04, Dthetas, DDthetas) and propagates, base to tip, the pose in {W}, the body twist
``V = (omega, v)`` and the body spatial acceleration ``dV`` of every moving link (Lynch & Park
eqs. 8.50-8.51, the forward iterations of recursive Newton-Euler):

    V_i  = Ad_{T_i,p} V_p + A_i dq_i
    dV_i = Ad_{T_i,p} dV_p + ad_{V_i} A_i dq_i + A_i ddq_i

with ``A_i`` the joint's screw axis in the child frame: (e_z, 0) for the revolute hinges and
pivots, (0, e_x) for the slides. Each closed chain is cut at the rod-end pivot {Tc} (seed eq.
frames) into two serial chains off the parent link:

- boom: revolute at the boom hinge {B1}, rotation Rz(alpha + theta - joint_offset) in the
  parent, joint rate dtheta (eq. Dthetas with theta = psi - q, see mechanism);
- cylinder: revolute at the base pivot {Bc}, rotation Rz(alpha + q1) in the parent, rate
  dq1 = k2 dx and acceleration ddq1 = dk2 dx + k2 ddx (eqs. dq__, 04);
- rod: slide along the cylinder's x axis by Lc0 + x, rate dx and acceleration ddx, where
  (x, dx, ddx) follow from (theta, dtheta, ddtheta) through eqs. qus_a, k1_3 and 04.

The telescope rod slides by rod_offset + xt2 along x of {P22}, fixed on the tilt boom. Frames
and links are those of :mod:`hiab_sim.crane.description`; {W} has y up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.crane import mechanism
from hiab_sim.crane.description import ClosedChain, Crane, LinkLengths
from hiab_sim.crane.kinematics import rotation_z
from hiab_sim.crane.names import BASE, LINK_NAMES, TELESCOPE, TELESCOPE_ROD, boom_link, cylinder_link, rod_link
from hiab_sim.dynamics.spatial import ad, rotate, twist_to_child

#: Moving links in base-to-tip order (each link's parent comes before it).
MOVING_LINKS = LINK_NAMES[1:]  # every link but the fixed base, parents first
_REVOLUTE_Z = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
_PRISMATIC_X = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0])


@dataclass(frozen=True)
class LinkMotion:
    """Motion of one link over T samples.

    ``rotation`` (T, 3, 3) and ``position`` (T, 3) [m]: the link frame in {W};
    ``twist`` (T, 6): body twist (omega [rad/s], v [m/s]) in the link frame;
    ``acceleration`` (T, 6): body spatial acceleration dV/dt [rad/s^2, m/s^2] in the link frame.
    """

    rotation: Array
    position: Array
    twist: Array
    acceleration: Array


@dataclass(frozen=True)
class ActuatorState:
    """Stroke x [m], velocity dx [m/s] and acceleration ddx [m/s^2] of one actuator, each (T,)."""

    stroke: Array
    velocity: Array
    acceleration: Array


@dataclass(frozen=True)
class CraneMotion:
    """Motion of every moving link (see :data:`MOVING_LINKS`) and of the three actuators."""

    links: dict[str, LinkMotion]
    actuators: dict[str, ActuatorState]  # "lift", "tilt", "telescope"


def _child(parent: LinkMotion, R: Array, p: Array, axis: Array, rate: Array, acc: Array) -> LinkMotion:
    """Propagate a link's motion to a child at pose (R, p) in it, moving along screw ``axis``."""
    joint_twist = axis * rate[:, None]
    twist = twist_to_child(R, p, parent.twist) + joint_twist
    acceleration = twist_to_child(R, p, parent.acceleration) + ad(twist, joint_twist) + axis * acc[:, None]
    return LinkMotion(
        rotation=parent.rotation @ R,
        position=parent.position + rotate(parent.rotation, p),
        twist=twist,
        acceleration=acceleration,
    )


def _add_chain(
    links: dict[str, LinkMotion],
    chain: ClosedChain,
    lengths: LinkLengths,
    theta: Array,
    dtheta: Array,
    ddtheta: Array,
) -> ActuatorState:
    """Add the boom, cylinder and rod of one closed chain (eqs. qus .. DDthetas)."""
    xi = getattr(lengths, chain.name)
    x, dx, ddx = mechanism.joint_to_actuator(chain, xi, theta, dtheta, ddtheta)
    _, q1, _ = mechanism.triangle_angles(x, xi.L, chain.L1, xi.x0)
    _, k2, _ = mechanism.velocity_ratios(x, xi.L, chain.L1, xi.x0)
    _, dk2, _ = mechanism.velocity_ratio_rates(x, dx, xi.L, chain.L1, xi.x0)
    parent = links[chain.parent]
    links[boom_link(chain.name)] = _child(
        parent,
        rotation_z(chain.base_axis_angle + mechanism.boom_rotation(chain, theta)),
        chain.boom_hinge,
        _REVOLUTE_Z,
        dtheta,
        ddtheta,
    )
    cylinder = _child(
        parent,
        rotation_z(chain.base_axis_angle + q1),
        chain.base_pivot(xi),
        _REVOLUTE_Z,
        k2 * dx,
        dk2 * dx + k2 * ddx,
    )
    links[cylinder_link(chain.name)] = cylinder
    slide = np.zeros((x.shape[0], 3))
    slide[:, 0] = xi.Lc0 + x
    links[rod_link(chain.name)] = _child(cylinder, np.eye(3), slide, _PRISMATIC_X, dx, ddx)
    return ActuatorState(x, dx, ddx)


def crane_motion(
    crane: Crane, lengths: LinkLengths, position: Array, velocity: Array, acceleration: Array
) -> CraneMotion:
    """Poses, twists and spatial accelerations of all links from joint samples, each (T, 3).

    Columns are (theta1 [rad], theta2 [rad], xt2 [m]) and their first and second time
    derivatives. Inputs are not validated here; see
    :func:`hiab_sim.dynamics.analytic_id.analytic_inverse_dynamics`.
    """
    n = position.shape[0]
    links = {
        BASE: LinkMotion(
            rotation=np.broadcast_to(np.eye(3), (n, 3, 3)),
            position=np.zeros((n, 3)),
            twist=np.zeros((n, 6)),
            acceleration=np.zeros((n, 6)),
        )
    }
    actuators = {}
    for column, chain in enumerate(crane.chains):
        actuators[chain.name] = _add_chain(
            links,
            chain,
            lengths,
            position[:, column],
            velocity[:, column],
            acceleration[:, column],
        )
    tele = crane.telescope
    R = np.asarray(tele.cylinder_frame.rotation)
    xt2, dxt2, ddxt2 = position[:, 2], velocity[:, 2], acceleration[:, 2]
    p = np.asarray(tele.cylinder_frame.position) + np.outer(tele.rod_offset + xt2, R[:, 0])
    links[TELESCOPE_ROD] = _child(links[tele.parent], R, p, _PRISMATIC_X, dxt2, ddxt2)
    actuators[TELESCOPE] = ActuatorState(xt2.copy(), dxt2.copy(), ddxt2.copy())
    del links[BASE]
    return CraneMotion(links=links, actuators=actuators)

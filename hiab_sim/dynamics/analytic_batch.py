"""The analytic inverse dynamics of many link-length sets at once: designs stacked into the sample axis.

The planar Newton-Euler solve of :mod:`hiab_sim.dynamics.analytic_planar` is elementwise in the
samples; the design enters only through a few constants of its :class:`PlanarModel` (per chain:
the cylinder base pivot z_Bc = z_B1 - L e^{i beta}, x0 = Lc0 + Lc and Lc0; per cylinder and
rod link: mass, centre of mass and I_zz). Giving every sample its own copy of those constants
evaluates D designs at T joint samples in one pass over D T samples, with no Python loop over
designs.

Cylinder and rod scale as slender bodies (:meth:`hiab_sim.config.Crane.bodies_for`): every body
of a cylinder link scales by f = x0 / x0_default, of a rod link by f = Lc / Lc_default, with
mass and centre of mass ~ f and the transverse inertia ~ f^3. A link's combined mass, centre of
mass and I_zz = sum (I_zz,b + m_b |c_b - c|^2) therefore scale the same way (f, f, f^3), so the
stacked model is the default design's, scaled. Tests hold this path to the per-design path.

No admissibility check is made here (a map marks inadmissible designs by their stroke margins);
use :func:`hiab_sim.dynamics.analytic_id.analytic_inverse_dynamics` for one checked design.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.arrays import Array
from hiab_sim.crane.description import Crane
from hiab_sim.crane.names import cylinder_link, rod_link
from hiab_sim.dynamics.analytic_planar import PlanarInertia, PlanarModel, planar_model, planar_solve
from hiab_sim.errors import InvalidInputError


def stacked_model(crane: Crane, xi: Array, samples: int) -> PlanarModel:
    """Planar model of designs xi (D, 6) [m], each constant repeated ``samples`` times: fields (D samples,)."""
    xi = np.asarray(xi, dtype=float)
    if xi.ndim != 2 or xi.shape[1] != 6:
        raise InvalidInputError(
            "xi", f"shape {xi.shape}", "must have shape (D, 6): lift L, Lc0, Lc, tilt L, Lc0, Lc", "m"
        )
    if not np.all(np.isfinite(xi)) or np.any(xi <= 0.0):
        raise InvalidInputError("xi", "a non-positive or non-finite length", "every length must be finite and > 0", "m")
    default = planar_model(crane, crane.default_lengths)
    links = dict(default.links)
    pivot: dict[str, complex | NDArray[np.complex128]] = {}
    x0: dict[str, float | Array] = {}
    lc0: dict[str, float | Array] = {}
    for j, chain in enumerate(crane.chains):
        L, Lc0, Lc = (np.repeat(xi[:, 3 * j + k], samples) for k in range(3))
        ref = chain.default_lengths
        for link, factor in ((cylinder_link(chain.name), (Lc0 + Lc) / ref.x0), (rod_link(chain.name), Lc / ref.Lc)):
            base = default.links[link]
            links[link] = PlanarInertia(
                mass=base.mass * factor,
                com=np.asarray(base.com * factor, dtype=np.complex128),
                inertia=base.inertia * factor**3,
            )
        pivot[chain.name] = default.hinge[chain.name] - L * np.exp(1j * chain.base_axis_angle)
        x0[chain.name] = Lc0 + Lc
        lc0[chain.name] = Lc0
    return replace(default, links=links, pivot=pivot, x0=x0, Lc0=lc0)


def batched_inverse_dynamics(
    crane: Crane,
    xi: ArrayLike,
    position: ArrayLike,
    velocity: ArrayLike,
    acceleration: ArrayLike,
    tcp_force: ArrayLike | None = None,
) -> tuple[Array, Array, Array, Array]:
    """Actuator forces [N], velocities [m/s], accelerations [m/s^2] and strokes [m] of D designs.

    Args:
        crane: The crane.
        xi: Link-length sets (D, 6) [m] (lift L, Lc0, Lc, tilt L, Lc0, Lc).
        position: Joint samples (T, 3) (theta1, theta2 [rad], xt2 [m]) shared by every design, or
            (D, T, 3), one trajectory per design.
        velocity: Their rates, same shape.
        acceleration: Their second derivatives, same shape.
        tcp_force: Force of the environment on the TCP in {W} [N], (3,), (T, 3) (one per joint
            sample, the same for every design) or None.

    Returns:
        Four arrays (D, T, 3): force, velocity, acceleration and stroke of lift, tilt and telescope.

    """
    xi = np.atleast_2d(np.asarray(xi, dtype=float))
    q = np.asarray(position, dtype=float)
    dq = np.asarray(velocity, dtype=float)
    ddq = np.asarray(acceleration, dtype=float)
    D, T = xi.shape[0], q.shape[-2]
    force = np.zeros(3) if tcp_force is None else np.asarray(tcp_force, dtype=float)
    if force.shape not in ((3,), (T, 3)):
        raise InvalidInputError("tcp_force", f"shape {force.shape}", f"must have shape (3,) or ({T}, 3)", "N")
    external = np.broadcast_to(force, (D * T, 3)) if force.ndim == 1 else np.tile(force, (D, 1))
    model = stacked_model(crane, xi, T)
    if q.ndim == 3:
        if q.shape != (D, T, 3) or dq.shape != q.shape or ddq.shape != q.shape:
            raise InvalidInputError("position", f"shape {q.shape}", f"must be ({D}, T, 3) like velocity, acceleration")
        q, dq, ddq = (x.reshape(D * T, 3) for x in (q, dq, ddq))
    else:
        q, dq, ddq = (np.tile(x, (D, 1)) for x in (q, dq, ddq))
    out = planar_solve(crane, model, q, dq, ddq, external)
    return tuple(a.reshape(D, T, 3) for a in out)  # type: ignore[return-value]

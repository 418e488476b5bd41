"""Lowest natural frequencies and mode shapes of the machine on its drive trains' axial stiffness.

Stiffness of one drive train between its pins (THK General Catalog, Ball Screw, "Studying the
Rigidity": the feed screw system's 1/K = 1/K_s + 1/K_N + 1/K_B, here with the pins in series):

    1/k = (l_0 + x) / (E A_r) + 1/k_nut + 1/k_bearing + n_pin / k_pin        [m/N],

with the screw a bar of root section A_r = pi d_r^2 / 4 between its fixed bearing and the nut,
l_0 at zero stroke and growing with the stroke x (:func:`hiab_sim.emla.drive_stiffness.axial_stiffness`,
the one formula the closed loop's drive train reads too).
The motor side is held (the brake or a stiff position loop): the frequencies are the locked-rotor
ones, the anti-resonances of each drive's two-mass model and the lowest resonance the load can
show a velocity loop.

Linearised dynamics at a static pose q (independent joints, n = 3). Kinetic energy dq^T M(q) dq / 2
with M = sum_i J_i^T G_i J_i over the moving links (G_i the spatial inertia about the link frame,
J_i its body twist per unit joint rate, :func:`hiab_sim.dynamics.analytic_kinematics.crane_motion`);
potential energy gravity's V(q) plus sum_a k_a (x_a(q) - r_a)^2 / 2 with the springs' rest lengths
r_a set so that q is an equilibrium: the springs carry the static actuator forces f(q). Its
Hessian is

    K = J_x^T diag(k) J_x + J_x^T df/dq,        J_x = dx/dq (actuator strokes per joint),

the second term the load's geometric stiffness, V_qq - sum_a f_a d^2x_a/dq^2 (from differentiating
V_q = J_x^T f(q), the static inverse dynamics), taken by central differences of the analytic
static inverse dynamics and symmetrised; it is below 1 % of the first on the XS 031. Then
K phi = omega^2 M phi (``scipy.linalg.eigh``), f = omega / (2 pi). Mode shapes phi are
M-normalised (phi^T M phi = 1) in joint coordinates; ``J_x phi`` gives them in actuator strokes.

The MuJoCo mass matrix (``mj_fullM`` projected through the loop Jacobian,
:mod:`hiab_sim.structure.natural_frequency_mujoco`) is the second path for M; a free-vibration
simulation of the spring-mounted MuJoCo model (:mod:`hiab_sim.structure.free_vibration`) checks
the frequencies.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_range
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.dynamics.analytic_batch import batched_inverse_dynamics
from hiab_sim.dynamics.analytic_id import link_inertias
from hiab_sim.dynamics.analytic_kinematics import crane_motion
from hiab_sim.emla.config import EmlaSet
from hiab_sim.emla.drive_stiffness import axial_stiffness
from hiab_sim.errors import InvalidInputError
from hiab_sim.structure.actuators import actuators

#: Central-difference step of the geometric stiffness [rad or m].
GEOMETRIC_STEP = 1e-6


def _unit_motions(crane: Crane, lengths: LinkLengths, position: Array) -> list:
    """Crane motions at the poses with one unit joint rate each (zero acceleration)."""
    T, n = position.shape
    out = []
    for k in range(n):
        rate = np.zeros((T, n))
        rate[:, k] = 1.0
        out.append(crane_motion(crane, lengths, position, rate, np.zeros((T, n))))
    return out


def mass_matrix(
    crane: Crane, lengths: LinkLengths, position: ArrayLike, payload_kg: float = 0.0
) -> tuple[Array, Array]:
    """Joint-space mass matrix M (T, n, n) [kg, kg m, kg m^2] and actuator Jacobian J_x = dx/dq (T, n_a, n).

    ``payload_kg``: a point mass rigidly held at the TCP, adding m J_tcp^T J_tcp (J_tcp the TCP's
    velocity per unit joint rate).
    """
    q = np.atleast_2d(np.asarray(position, dtype=float))
    motions = _unit_motions(crane, lengths, q)
    T, n = q.shape
    M = np.zeros((T, n, n))
    for name, inertia in link_inertias(crane, lengths).items():
        J = np.stack([m.links[name].twist for m in motions], axis=-1)  # (T, 6, n)
        M += np.einsum("tik,ij,tjl->tkl", J, inertia.spatial, J)
    if payload_kg > 0.0:
        carrier = next(f"{a.name}_rod" for a in actuators(crane) if a.chain is None)
        point = np.asarray(crane.tcp_in_telescope_rod.position)
        Jp = np.stack(
            [m.links[carrier].twist[:, 3:] + np.cross(m.links[carrier].twist[:, :3], point) for m in motions], axis=-1
        )  # (T, 3, n), in the carrier's axes
        M += payload_kg * np.einsum("tik,til->tkl", Jp, Jp)
    names = [a.name for a in actuators(crane)]
    Jx = np.stack([np.stack([m.actuators[a].velocity for m in motions], axis=-1) for a in names], axis=1)
    return 0.5 * (M + np.swapaxes(M, 1, 2)), Jx


def static_forces(crane: Crane, lengths: LinkLengths, position: Array, tcp_force: ArrayLike | None) -> Array:
    """Actuator forces holding static poses (T, n_a) [N] (analytic inverse dynamics)."""
    zero = np.zeros_like(position)
    external = None if tcp_force is None else np.asarray(tcp_force, dtype=float)
    return batched_inverse_dynamics(crane, lengths.as_array()[None], position, zero, zero, external)[0][0]


def geometric_stiffness(
    crane: Crane, lengths: LinkLengths, position: ArrayLike, jx: Array, tcp_force: ArrayLike | None = None
) -> Array:
    """J_x^T df/dq of the static actuator forces, symmetrised (T, n, n) (module docstring)."""
    return differenced_stiffness(lambda q: static_forces(crane, lengths, q, tcp_force), position, jx)


def differenced_stiffness(forces: Callable[[Array], Array], position: ArrayLike, jx: Array) -> Array:
    """J_x^T df/dq, symmetrised (T, n, n): central differences (step :data:`GEOMETRIC_STEP`) of ``forces(q)``.

    ``forces``: the static actuator forces (T, n_a) [N] at joint samples q (T, n); ``jx`` (T, n_a, n).
    """
    q = np.atleast_2d(np.asarray(position, dtype=float))
    T, n = q.shape
    df = np.zeros((T, jx.shape[1], n))
    for k in range(n):
        step = np.zeros(n)
        step[k] = GEOMETRIC_STEP
        df[:, :, k] = (forces(q + step) - forces(q - step)) / (2.0 * GEOMETRIC_STEP)
    K = np.einsum("tai,taj->tij", jx, df)
    return 0.5 * (K + np.swapaxes(K, 1, 2))


@dataclass(frozen=True)
class Modes:
    """Natural frequencies at T poses: ``frequency_Hz`` (T, n) ascending, ``shape`` (T, n, n) (columns, M-normalised).

    ``stiffness_N_per_m`` (T, n_a): each drive train's k at the pose; ``actuator_shape`` (T, n_a, n):
    the mode shapes in actuator strokes, J_x phi [m per unit modal coordinate].
    """

    frequency_Hz: Array
    shape: Array
    actuator_shape: Array
    stiffness_N_per_m: Array
    actuator_names: tuple[str, ...]

    @property
    def lowest_Hz(self) -> Array:
        """Lowest natural frequency at each pose (T,) [Hz]."""
        return self.frequency_Hz[:, 0]


def natural_frequencies(
    crane: Crane,
    emlas: EmlaSet,
    lengths: LinkLengths,
    position: ArrayLike,
    tcp_force: ArrayLike | None = None,
    mass: Array | None = None,
    actuator_jacobian: Array | None = None,
    payload_kg: float = 0.0,
) -> Modes:
    """Locked-rotor natural frequencies and mode shapes at static poses (T, n) (module docstring).

    Args:
        crane: The crane.
        emlas: EMLA set; every actuator needs ``screw`` and ``drive_stiffness`` data.
        lengths: Link lengths Xi [m].
        position: Joint samples (T, n) [rad, m].
        tcp_force: Force of the environment on the TCP in {W} [N], (3,) or (T, 3) (a payload), or None.
        mass: Optional mass matrix (T, n, n) from another path (MuJoCo); default the analytic one.
        actuator_jacobian: With ``mass``: J_x (T, n_a, n) from the same path.
        payload_kg: Mass held at the TCP [kg] (its inertia; its weight belongs in ``tcp_force``).

    """
    q = np.atleast_2d(np.asarray(position, dtype=float))
    check_range("payload_kg", payload_kg, 0.0, unit="kg")
    M, jx = mass_matrix(crane, lengths, q, payload_kg)
    if mass is not None:
        M = np.asarray(mass, dtype=float)
        jx = np.asarray(actuator_jacobian, dtype=float) if actuator_jacobian is not None else jx
    by_name = {p.name: p for p in emlas}
    acts = actuators(crane)
    motion = crane_motion(crane, lengths, q, np.zeros_like(q), np.zeros_like(q))
    k = np.stack([axial_stiffness(by_name[a.name], motion.actuators[a.name].stroke) for a in acts], axis=1)
    K = np.einsum("tai,ta,taj->tij", jx, k, jx) + geometric_stiffness(crane, lengths, q, jx, tcp_force)
    w2, shape = generalized_eigh(K, M)
    if np.any(w2 <= 0.0):
        raise InvalidInputError("stiffness", f"omega^2 = {w2.min():.3g}", "every pose must be stable (K > 0)")
    freq = np.sqrt(w2) / (2.0 * math.pi)
    return Modes(freq, shape, np.einsum("tai,tij->taj", jx, shape), k, tuple(a.name for a in acts))


def generalized_eigh(K: Array, M: Array) -> tuple[Array, Array]:
    """K phi = w M phi for stacks of symmetric K and SPD M (T, n, n): w ascending (T, n), phi^T M phi = I.

    With M = C C^T (Cholesky), A = C^-1 K C^-T is symmetric; its eigenvectors v give phi = C^-T v.
    """
    C = np.linalg.cholesky(M)
    Ci = np.linalg.inv(C)
    A = Ci @ K @ np.swapaxes(Ci, 1, 2)
    w, v = np.linalg.eigh(0.5 * (A + np.swapaxes(A, 1, 2)))
    return w, np.swapaxes(Ci, 1, 2) @ v


#: Largest velocity-loop bandwidth per unit lowest natural frequency the check accepts [-].
MAX_BANDWIDTH_RATIO = 1.0 / 3.0


def bandwidth_margin(bandwidth_Hz: float, lowest_Hz: ArrayLike, max_ratio: float = MAX_BANDWIDTH_RATIO) -> float:
    """Margin 1 - f_bw / (max_ratio f_1,min) [-] of a velocity-loop bandwidth against the lowest frequency.

    >= 0 holds: the loop's bandwidth stays below ``max_ratio`` times the lowest natural frequency
    over the poses. The rule of servo tuning guides is that the velocity loop must stay well below
    the first mechanical resonance (G. Ellis, Control System Design Guide, the chapter on
    mechanical resonance); ``max_ratio`` = 1/3 is our choice of "well below", the lenient end of
    the 1/3 to 1/5 of common practice. The frequencies here are the locked-rotor ones, the anti-resonances of the
    drives' two-mass models, which lie below their resonances: 1/3 of them is the stricter reading.
    """
    check_range("bandwidth_Hz", bandwidth_Hz, 0.0, low_open=True, unit="Hz")
    check_range("max_ratio", max_ratio, 0.0, 1.0, low_open=True)
    return 1.0 - bandwidth_Hz / (max_ratio * float(np.min(lowest_Hz)))


def working_range_poses(crane: Crane, counts: tuple[int, ...] = (9, 9, 3)) -> Array:
    """A grid of static poses (N, n) over every joint's working range (the chains', then the direct joint's)."""
    ranges = [chain.joint_range for chain in crane.chains] + [crane.telescope.joint_range]
    if len(counts) != len(ranges) or any(isinstance(c, bool) or int(c) != c or c < 1 for c in counts):
        raise InvalidInputError("counts", list(counts), f"must be {len(ranges)} positive integers")
    axes = [
        np.linspace(lo, hi, int(c)) if c > 1 else np.array([0.5 * (lo + hi)])
        for (lo, hi), c in zip(ranges, counts, strict=True)
    ]
    return np.stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")], axis=1)

"""Two-mass drive train per EMLA: the motor side on a spring with free play to the rod.

Coordinates at the rod (the motor angle divided by k = 2 pi G / rho): the motor side x_m with mass
m_m = J_m k^2 + M_sm (the rotor and screw inertia reflected to the rod, eq. ``torque_torque`` x k),
the rod x (the MuJoCo slide). With the deflection d = x_m - x, the free play 2 b and the contact
deflection e = d - b (d > b), d + b (d < -b), 0 otherwise,

    f_s = k_s e + c_s (v_m - v)     while in contact, never pulling across the gap (sign of e kept),
    m_m dv_m/dt = f_drive - b_f v_m - f_s,

f_drive = k (tau_m - tau_f tanh(omega_m / omega_eps)) from the drive (:mod:`hiab_sim.emla.drive_sim`),
b_f the screw's viscous friction (it acts at the screw's speed, the motor side's), and f_s the force
on the rod. c_s = 2 zeta sqrt(k_s m_m) damps the locked-rod mode.

Integration. The rod side is the slide's actuator, affine in the rod's stroke and rate,
f = ctrl - k_c x - c_c v (:meth:`TwoMassDriveTrain.rod_actuator`), with (k_c, c_c) = (k_s, c_s + k_s h)
in contact and 0 in the gap, and ctrl = k_s x_anchor + c_s v_m. MuJoCo's ``implicitfast`` step takes
the rate terms at the new rate v', so the spring acts at the predicted stroke x + h v': backward
Euler for the spring, stable however light the rod side (the telescope's slide sees 76 kg, the
two boom slides together a few kg in some directions: an explicit spring of 1.9e8 N/m would need a
step below 0.1 ms). Its price is a numerical damping k_s h, zeta_num = omega h / 2 of a mode
(0.04 for the lowest, 12.5 Hz, at h = 1 ms), counted with the spring's damping; the frequency
is kept to (omega h)^2 / 8. The motor side then takes the force the rod received, f = ctrl - k_c x
- c_c v' (action and reaction), in a symplectic Euler step with the screw friction implicit.

Two-mass frequency with the rod on a load m_L: omega^2 = k_s (1/m_m + 1/m_L); its lowest value,
the rod locked (m_L -> infinity), is omega_lock = sqrt(k_s / m_m), one of the bounds the controller's
bandwidth is designed against (:func:`locked_rod_frequency_Hz`).

Stiffness. k_s is the EMLA file's (``drive_stiffness``, :func:`hiab_sim.emla.drive_stiffness.axial_stiffness`,
the series of screw, nut, bearing and pins that the structure's natural frequencies use), one value
per drive, taken at the planned motion's mean stroke (:func:`drive_train_stiffness`): the screw's
share grows with the stroke, so along the default study's motion k_s varies by about +-7 % (lift,
tilt) and -14 % to +11 % (telescope) around it; a spring that changes with the stroke would need the
force -1/2 dk/dx e^2 to stay conservative, a constant one per cycle is the choice here.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.emla.config import EmlaSet
from hiab_sim.emla.drive_stiffness import axial_stiffness
from hiab_sim.env.plant.config import DriveTrain
from hiab_sim.errors import InvalidInputError


def drive_train_stiffness(emlas: EmlaSet, stroke: Array) -> Array:
    """k_s [N/m] per drive: the EMLA file's axial stiffness at the mean of the planned strokes (N, n_a) [m].

    Raises:
        InvalidInputError: an EMLA of the set has no ``screw`` or ``drive_stiffness`` data.

    """
    params = emlas.as_tuple()
    missing = [p.name for p in params if p.screw is None or p.stiffness is None]
    if missing:
        raise InvalidInputError(
            "drive_train", ", ".join(missing), "needs the EMLA file's screw and drive_stiffness sections (its k_s)"
        )
    mean = np.mean(np.atleast_2d(np.asarray(stroke, dtype=float)), axis=0)
    return np.array([float(axial_stiffness(p, x)) for p, x in zip(params, mean, strict=True)])


def locked_rod_frequency_Hz(stiffness: Array, motor_mass: Array) -> Array:
    """sqrt(k_s / m_m) / 2 pi [Hz] per drive for k_s [N/m] and m_m [kg]: the lowest two-mass frequency."""
    return np.sqrt(np.asarray(stiffness, dtype=float) / np.asarray(motor_mass, dtype=float)) / (2.0 * math.pi)


class TwoMassDriveTrain:
    """Motor-side states of n drives and their springs with free play (module docstring).

    Args:
        train: Damping ratio and free play.
        stiffness: k_s per drive [N/m] (:func:`drive_train_stiffness`).
        motor_mass: m_m per drive [kg].
        viscous: b_f per drive [N s/m], acting on the motor side.

    """

    def __init__(self, train: DriveTrain, stiffness: Array, motor_mass: Array, viscous: Array) -> None:
        self.mass = np.asarray(motor_mass, dtype=float)
        self.stiffness = np.broadcast_to(np.asarray(stiffness, dtype=float), self.mass.shape).copy()
        self.half_play = 0.5 * train.backlash_m
        self.damping = 2.0 * train.damping_ratio * np.sqrt(self.stiffness * self.mass)
        self.viscous = np.asarray(viscous, dtype=float)
        self.position = np.zeros_like(self.mass)
        self.velocity = np.zeros_like(self.mass)
        # the constants as floats for the per-step scalar loops
        self._stiffness = self.stiffness.tolist()
        self._damping = self.damping.tolist()
        self._mass = self.mass.tolist()
        self._viscous = np.broadcast_to(self.viscous, self.mass.shape).tolist()

    def reset(self, rod_position: Array, rod_velocity: Array, force: Array) -> None:
        """Put the motor side where the spring carries ``force`` [N] at rest relative to the rod."""
        force = np.asarray(force, dtype=float)
        offset = force / self.stiffness + self.half_play * np.sign(force)
        self.position = np.asarray(rod_position, dtype=float) + offset
        self.velocity = np.asarray(rod_velocity, dtype=float).copy()

    def contact_deflection(self, rod_position: Array) -> Array:
        """e: the deflection beyond the free play [m] (0 inside the gap)."""
        d = self.position - rod_position
        return np.where(d > self.half_play, d - self.half_play, np.where(d < -self.half_play, d + self.half_play, 0.0))

    def spring_force(self, rod_position: Array, rod_velocity: Array) -> Array:
        """f_s [N] on the rod, positive extending (module docstring).

        Per drive in scalar Python, as :meth:`rod_actuator` and :meth:`step`: called every physics step
        on a few drives, where numpy's per-call cost would exceed the arithmetic.
        """
        b = self.half_play
        forces = []
        for x_m, v_m, x, v, k_s, c_s in zip(
            self.position.tolist(),
            self.velocity.tolist(),
            np.asarray(rod_position, dtype=float).tolist(),
            np.asarray(rod_velocity, dtype=float).tolist(),
            self._stiffness,
            self._damping,
            strict=True,
        ):
            d = x_m - x
            if d > b:
                force = k_s * (d - b) + c_s * (v_m - v)
                forces.append(force if force > 0.0 else 0.0)
            elif d < -b:
                force = k_s * (d + b) + c_s * (v_m - v)
                forces.append(force if force < 0.0 else 0.0)
            else:
                forces.append(0.0)
        return np.array(forces)

    def rod_actuator(self, rod_position: Array, h: float) -> tuple[Array, Array, Array]:
        """(ctrl [N], k_c [N/m], c_c [N s/m]) of the rod's actuator f = ctrl - k_c x - c_c v (module docstring)."""
        ctrl, k_c, c_c = self._rod_actuator(np.asarray(rod_position, dtype=float).tolist())
        return np.array(ctrl), np.array(k_c), np.array(c_c)

    def _rod_actuator(self, rod_position: list[float]) -> tuple[list[float], list[float], list[float]]:
        """:meth:`rod_actuator` on lists of floats."""
        b = self.half_play
        ctrl, k_c, c_c = [], [], []
        for x_m, v_m, x, k_s, c_s in zip(
            self.position.tolist(), self.velocity.tolist(), rod_position, self._stiffness, self._damping, strict=True
        ):
            d = x_m - x
            if d > b:
                k, c, anchor = k_s, c_s, x_m - b
            elif d < -b:
                k, c, anchor = k_s, c_s, x_m + b
            else:
                k, c, anchor = 0.0, 0.0, x_m
            ctrl.append(k * anchor + c * v_m)
            k_c.append(k)
            c_c.append(c)
        return ctrl, k_c, c_c

    def spring_energy(self, rod_position: Array) -> Array:
        """1/2 k_s e^2 [J] per drive."""
        e = self.contact_deflection(rod_position)
        return 0.5 * self.stiffness * e * e

    def kinetic_energy(self) -> Array:
        """1/2 m_m v_m^2 [J] per drive."""
        return 0.5 * self.mass * self.velocity**2

    def step(self, drive_force: Array, rod_force: Array, rod_velocity: Array, h: float) -> Array:
        """Advance the motor side by h [s] under the drive's force and the rod's reaction [N].

        Returns:
            The energy the drive train dissipated over the step [J]: the screw friction b_f v_m^2 h, the
            spring's damping c_s (v_m - v')^2 h and the numerical k_s h^2 v'^2 (module docstring).

        """
        return np.array(
            self._step(
                np.asarray(drive_force, dtype=float).tolist(),
                np.asarray(rod_force, dtype=float).tolist(),
                np.asarray(rod_velocity, dtype=float).tolist(),
                h,
            )
        )

    def _step(
        self, drive_force: list[float], rod_force: list[float], rod_velocity: list[float], h: float
    ) -> list[float]:
        """:meth:`step` on lists of floats."""
        positions, velocities, dissipated = [], [], []
        for x_m, v_m, f_d, f_r, v, m, c_s, b_f in zip(
            self.position.tolist(),
            self.velocity.tolist(),
            drive_force,
            rod_force,
            rod_velocity,
            self._mass,
            self._damping,
            self._viscous,
            strict=True,
        ):
            slip = v_m - v
            spring = h * c_s * slip * slip if f_r != 0.0 else 0.0
            # Screw friction implicit (-b_f v_m at the new rate): its work over the step is -b_f v_m^2 h exactly.
            v_m = (v_m + h * (f_d - f_r) / m) / (1.0 + h * b_f / m)
            positions.append(x_m + h * v_m)
            velocities.append(v_m)
            dissipated.append(h * b_f * (v_m * v_m) + spring)
        self.position = np.array(positions)
        self.velocity = np.array(velocities)
        return dissipated


def coupled_step(
    train: TwoMassDriveTrain,
    model: mujoco.MjModel,
    data: mujoco.MjData,
    actuators: NDArray[np.int64],
    dofs: NDArray[np.int64],
    drive_force: Array,
    h: float,
) -> Array:
    """One physics step of the rods (``mj_step``) and the motor sides on their springs; return the loss [J].

    ``actuators`` are the slides' affine actuators (gain 1, bias (0, -k_c, -c_c)), ``dofs`` the slides'
    degrees of freedom; see the module docstring.
    """
    x = data.qpos[dofs].tolist()
    ctrl, k_c, c_c = train._rod_actuator(x)
    data.ctrl[actuators] = ctrl
    bias = model.actuator_biasprm
    bias[actuators, 1] = [-k for k in k_c]
    bias[actuators, 2] = [-c for c in c_c]
    mujoco.mj_step(model, data)
    v_new = data.qvel[dofs].tolist()
    # what the rod received over the step
    force = [u - k * x_j - c * v for u, k, x_j, c, v in zip(ctrl, k_c, x, c_c, v_new, strict=True)]
    return np.array(train._step(np.asarray(drive_force, dtype=float).tolist(), force, v_new, h))

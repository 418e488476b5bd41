"""Optional drive losses beyond the paper's model: transmission efficiency, inverter loss, holding brake.

Every option defaults to "off" and then contributes an exact 0.0, so the paper's powers are
reproduced bit for bit. Each comes in an exact form (reported) and a smooth form (the solver's).

Transmission (gearbox + screw) efficiency, direction dependent. The screw carries f_sm
(eq. ``torque_force``); power flows motor -> load (forward, f_sm v_x > 0) or load -> motor
(backdriven, f_sm v_x < 0). The motor-side torque is tau_t = f_sm / k + tau_tr (k = 2 pi G / rho)
with the loss torque

    tau_tr = (sign(omega_m) / k) (a |f_sm| + b f_sm sign(omega_m)),
    a = ((1/eta_fwd - 1) + (1 - eta_back)) / 2,  b = ((1/eta_fwd - 1) - (1 - eta_back)) / 2,

so tau_t omega_m = f_sm v_x / eta_fwd forward and f_sm v_x eta_back backdriven, and the loss power
tau_tr omega_m = |f_sm v_x| (1/eta_fwd - 1) or (1 - eta_back) is never negative. At standstill the
loss torque is 0: a holding torque f_sm / k lies between the backdriving and forward torques, so
it holds (standstill is |omega_m| <= 1e-9 omega_eps, round-off of a zero speed included). Smooth form:
sign(omega_m) -> tanh(omega_m / omega_eps) (the rotor friction's regularisation) and
|f_sm| -> sqrt(f_sm^2 + f_eps^2); the loss power stays >= 0 because a >= |b|.

Inverter loss (DC side minus motor terminals), with the phase current amplitude I = |i_q| (i_d = 0):

    P_inv = c0 + c1 I + c2 I^2

c0 [W] standby (control, gate drives), c1 [W/A] switching and semiconductor threshold voltage,
c2 [ohm] semiconductor on-resistance. Smooth form: I -> sqrt(i_q^2 + i_eps^2) - i_eps, which is
0 at zero current and within i_eps of |i_q| everywhere, so |P_inv,smooth - P_inv| <= c1 i_eps.
Likewise the smooth |f_sm| is within f_eps of the exact one, so away from standstill
(|omega_m| >> omega_eps, where tanh = sign to within 2 exp(-2 |omega_m| / omega_eps)) the smooth
transmission loss torque is within a f_eps / k of the exact one.

Holding brake (spring applied, released by its coil while moving). Exact: engaged where
|v_x| < v_b; there the motor carries no current, the brake carries the load, and the drive draws
only c0. While released the coil draws P_coil. With s = 1 (released) or 0 (engaged):

    P_elec = s (P_motor + P_coil) + P_inv(s I)

and the mechanical power f_x v_x in the hold band (zero at true standstill) is attributed to the
brake: ``brake_held_power`` = -(1 - s) f_x v_x. Smooth form: s = 1 - exp(-(v_x / v_b)^4), which is
0 with zero slope at standstill, 0.06 at v_b / 2, 0.63 at v_b and 0.99 at 1.5 v_b.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.checks import check_efficiency, check_fields

#: Motor speeds below this fraction of omega_eps are standstill in the exact transmission loss: there the
#: smooth form's tanh is below 1e-9, so exact and smooth agree; above round-off of a zero speed (~1e-12 rad/s).
STANDSTILL_FRACTION = 1e-9


@dataclass(frozen=True)
class DriveLosses:
    """Optional drive-loss parameters of one EMLA; the defaults switch every option off.

    Attributes:
        transmission_efficiency_forward: eta_fwd in (0, 1], gearbox x screw, motor driving the load.
        transmission_efficiency_backdriven: eta_back in (0, 1], the load driving the motor.
        force_smoothing: f_eps [N] > 0 of the smooth |f_sm| (model choice).
        inverter_constant_loss: c0 [W] >= 0.
        inverter_current_loss: c1 [W/A] >= 0.
        inverter_resistance: c2 [ohm] >= 0.
        current_smoothing: i_eps [A] > 0 of the smooth |i_q| (model choice).
        brake_speed: v_b [m/s] >= 0; the holding brake is engaged below it (0: no brake).
        brake_coil_power: P_coil [W] >= 0 drawn by the released brake's coil.
        label: Prefix of error messages.

    """

    transmission_efficiency_forward: float = 1.0
    transmission_efficiency_backdriven: float = 1.0
    force_smoothing: float = 10.0
    inverter_constant_loss: float = 0.0
    inverter_current_loss: float = 0.0
    inverter_resistance: float = 0.0
    current_smoothing: float = 0.01
    brake_speed: float = 0.0
    brake_coil_power: float = 0.0
    label: str = "drive_losses"

    def __post_init__(self) -> None:
        check_efficiency(f"{self.label}.transmission_efficiency_forward", self.transmission_efficiency_forward)
        check_efficiency(f"{self.label}.transmission_efficiency_backdriven", self.transmission_efficiency_backdriven)
        check_fields(
            self,
            positive={"force_smoothing": "N", "current_smoothing": "A"},
            non_negative={
                "inverter_constant_loss": "W",
                "inverter_current_loss": "W/A",
                "inverter_resistance": "ohm",
                "brake_speed": "m/s",
                "brake_coil_power": "W",
            },
        )

    @property
    def transmission_on(self) -> bool:
        """True when either transmission efficiency is below 1."""
        return self.transmission_efficiency_forward < 1.0 or self.transmission_efficiency_backdriven < 1.0

    @property
    def inverter_on(self) -> bool:
        """True when any inverter loss coefficient is positive."""
        return max(self.inverter_constant_loss, self.inverter_current_loss, self.inverter_resistance) > 0.0

    @property
    def brake_on(self) -> bool:
        """True when the holding brake is modelled."""
        return self.brake_speed > 0.0

    def describe(self) -> str:
        """One line naming the options that are on (for figure titles and reports)."""
        parts = []
        if self.transmission_on:
            parts.append(
                f"transmission eta {self.transmission_efficiency_forward:g} fwd / "
                f"{self.transmission_efficiency_backdriven:g} back"
            )
        if self.inverter_on:
            parts.append(
                f"inverter {self.inverter_constant_loss:g} W + {self.inverter_current_loss:g} W/A I"
                f" + {self.inverter_resistance:g} ohm I^2"
            )
        if self.brake_on:
            parts.append(f"holding brake below {self.brake_speed * 1e3:g} mm/s")
        return "drive losses: " + ("; ".join(parts) if parts else "off (paper model)")


def transmission_loss_torque(
    losses: DriveLosses, screw_force: Array, motor_speed: Array, k: float, omega_eps: float, exact: bool
) -> tuple[Array, Array, Array]:
    """Return (tau_tr [N m], d tau_tr / d f_sm [m], d tau_tr / d omega_m [N m s]) of the module docstring.

    Args:
        losses: The drive-loss options.
        screw_force: f_sm [N].
        motor_speed: omega_m [rad/s].
        k: Transmission ratio 2 pi G / rho [rad/m].
        omega_eps: Speed regularisation [rad/s] of sign(omega_m) (the rotor friction's).
        exact: Exact sign and absolute value (derivatives are then those of the smooth branches' limits).

    """
    ef, eb = losses.transmission_efficiency_forward, losses.transmission_efficiency_backdriven
    a = 0.5 * ((1.0 / ef - 1.0) + (1.0 - eb))
    b = 0.5 * ((1.0 / ef - 1.0) - (1.0 - eb))
    f = screw_force
    if exact:
        # standstill below STANDSTILL_FRACTION omega_eps: a rest of the trajectory is zero only to round-off
        # (about 1e-12 rad/s), whose sign would pick the forward or the backdriving torque at random
        sgn = np.where(np.abs(motor_speed) > STANDSTILL_FRACTION * omega_eps, np.sign(motor_speed), 0.0)
        tau = sgn / k * (a * np.abs(f) + b * f * sgn)
        return tau, sgn / k * (a * np.sign(f) + b * sgn), np.zeros_like(f)
    x = motor_speed / omega_eps
    t = np.tanh(x)
    dt = (1.0 / np.cosh(np.clip(x, -350.0, 350.0)) ** 2) / omega_eps
    sabs = np.sqrt(f * f + losses.force_smoothing**2)
    tau = t / k * (a * sabs + b * f * t)
    d_f = t / k * (a * f / sabs + b * t)
    d_w = dt / k * (a * sabs + 2.0 * b * f * t)
    return tau, d_f, d_w


def inverter_loss(losses: DriveLosses, current: Array, exact: bool) -> tuple[Array, Array]:
    """Return (P_inv [W], dP_inv / d i [W/A]) for the q-axis current i [A] (exact or smooth |i|)."""
    i = current
    if exact:
        mag, d_mag = np.abs(i), np.sign(i)
    else:
        root = np.sqrt(i * i + losses.current_smoothing**2)
        mag, d_mag = root - losses.current_smoothing, i / root
    c0, c1, c2 = losses.inverter_constant_loss, losses.inverter_current_loss, losses.inverter_resistance
    return c0 + c1 * mag + c2 * i * i, c1 * d_mag + 2.0 * c2 * i


def brake_release(losses: DriveLosses, velocity: Array, exact: bool) -> tuple[Array, Array]:
    """Return (s, ds/dv_x [s/m]): 1 where the brake is released (moving), 0 where it holds."""
    v = velocity
    if not losses.brake_on:
        return np.ones_like(v), np.zeros_like(v)
    vb = losses.brake_speed
    if exact:
        return (np.abs(v) >= vb).astype(float), np.zeros_like(v)
    u = (v / vb) ** 4
    e = np.exp(-u)
    return 1.0 - e, e * 4.0 * v**3 / vb**4

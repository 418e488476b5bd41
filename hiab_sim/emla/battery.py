"""Battery energy of the EMLA drives on a shared DC bus: exact on the grid, and smooth for the solver.

Power flow (every power in W, per sample k and drive i):

* Drive i's inverter turns its motor electrical power P_i (eq. ``system_efficiency``'s
  denominator, :func:`hiab_sim.emla.electrical_power`) into a DC-bus power
  D_i = h_inv(P_i) with h_inv(x) = x / eta_inv while motoring (x > 0) and x eta_inv while
  generating (x < 0).
* The drives share one DC bus, so regeneration of one drive feeds the others first:
  B = sum_i D_i.
* The battery delivers P_bat = h_bat(B), h_bat(x) = x / eta_dis when the bus draws (x > 0) and
  x eta_ch when it returns power (x < 0, charging).
* Battery energy over the cycle: E_bat = int P_bat dt, by the trapezoid rule on the sample
  grid, the quadrature ``study/report.py`` uses for every energy. It is the net energy taken
  from the battery (negative only if the cycle returns more than it draws).

Each h is piecewise linear with one kink at 0: h(x) = beta x + (alpha - beta) max(x, 0) with
alpha = 1/eta >= 1 >= beta = eta (or 1/eta_dis, eta_ch). For the solver, max(x, 0) is replaced by
the softplus s_eps(x) = eps log(1 + exp(x / eps)), eps = ``smoothing_power`` [W]. The smooth h is
C-infinity and convex (alpha >= beta), and 0 < s_eps(x) - max(x, 0) <= eps ln 2 (largest at
x = 0), so

    |E_smooth - E_exact| <= eps ln 2 (n (alpha_inv - beta_inv) alpha_bat + (alpha_bat - beta_bat)) T

for n drives over the duration T (h_bat is Lipschitz with constant alpha_bat): the smoothing error
is O(eps) and vanishes as eps -> 0 (tested).

Per-actuator drawn energy int max(P_i, 0) dt (motor side, no regeneration credited) is reported
alongside; :func:`battery_energy` returns both, and the two figures whose boundaries are often
confused:

* ``dc_bus_drawn_energy`` = int max(B, 0) dt: the positive part of the *shared* DC-bus power, which
  credits energy passed from one drive to another on the bus;
* ``no_regeneration_energy_at_battery`` = int sum_i max(D_i, 0) / eta_dis dt: the battery's energy
  if no drive could return power (every regenerated joule burnt in a braking resistor, no credit
  passed between drives).

The rest between cycles (:mod:`hiab_sim.emla.hold`) only draws power, so its battery energy is
linear, sum_i E_rest,i / (eta_inv eta_dis) (:func:`rest_battery_energy`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_efficiency
from hiab_sim.errors import InvalidInputError


@dataclass(frozen=True)
class BatteryParams:
    """DC bus and battery between the drives and the cells.

    Attributes:
        inverter_efficiency: eta_inv in (0, 1], each drive's inverter, both directions. Set it to 1
            when the drive-loss inverter model of :mod:`hiab_sim.emla.losses` is on (then P_i
            already is the DC-side power; counting both would charge the inverter twice).
        discharge_efficiency: eta_dis in (0, 1]: P_bat = B / eta_dis while the bus draws.
        charge_efficiency: eta_ch in (0, 1]: P_bat = B eta_ch while the bus returns power.
        smoothing_power: eps [W] > 0 of the softplus used by the smooth energy (a model choice).

    Defaults (also in the EMLA preset's ``battery`` section, with their provenance):
    eta_inv = 0.97 (estimate: 400 V servo inverters 0.95-0.98 at rated load), eta_dis = eta_ch =
    0.975 (estimate: Li-ion round trip about 0.95 at moderate C-rates, split evenly,
    sqrt(0.95) = 0.975), eps = 1 W (about 1e-4 of the drives' peak powers).

    """

    inverter_efficiency: float = 0.97
    discharge_efficiency: float = 0.975
    charge_efficiency: float = 0.975
    smoothing_power: float = 1.0

    def __post_init__(self) -> None:
        check_efficiency("battery.inverter_efficiency", self.inverter_efficiency)
        check_efficiency("battery.discharge_efficiency", self.discharge_efficiency)
        check_efficiency("battery.charge_efficiency", self.charge_efficiency)
        if not (math.isfinite(self.smoothing_power) and self.smoothing_power > 0):
            raise InvalidInputError("battery.smoothing_power", self.smoothing_power, "must be finite and > 0", "W")

    def smoothing_bound(self, n_drives: int, duration: float) -> float:
        """Return the bound [J] on |E_smooth - E_exact| stated in the module docstring."""
        a_inv, b_inv = 1.0 / self.inverter_efficiency, self.inverter_efficiency
        a_bat, b_bat = 1.0 / self.discharge_efficiency, self.charge_efficiency
        return self.smoothing_power * math.log(2.0) * (n_drives * (a_inv - b_inv) * a_bat + a_bat - b_bat) * duration


@dataclass(frozen=True)
class BatteryEnergy:
    """Battery energy of one power history (see the module docstring).

    Attributes:
        energy: E_bat [J] (exact kinks, or smooth when computed with ``smooth=True``).
        gradient: dE_bat/dP [J/W = s], shape (K, n): the sensitivity to each drive's power sample.
        bus_power: B [W], shape (K,).
        battery_power: P_bat [W], shape (K,).
        drawn_energy: int max(P_i, 0) dt [J] per drive, shape (n,) (always exact).
        net_energy: int P_i dt [J] per drive, shape (n,).
        dc_bus_drawn_energy: int max(B, 0) dt [J] on the shared bus (exact).
        no_regeneration_energy_at_battery: int sum_i max(D_i, 0) / eta_dis dt [J] (exact).

    """

    energy: float
    gradient: Array
    bus_power: Array
    battery_power: Array
    drawn_energy: Array
    net_energy: Array
    dc_bus_drawn_energy: float = 0.0
    no_regeneration_energy_at_battery: float = 0.0


def trapezoid_weights(time: ArrayLike) -> Array:
    """Return w with sum_k w_k y_k = trapezoid integral of y over ``time`` [s]; shape (K,)."""
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise InvalidInputError("time", f"shape {t.shape}", "must be one-dimensional with at least 2 samples")
    h = np.diff(t)
    if not np.all(h > 0):
        raise InvalidInputError("time", "not increasing", "must be strictly increasing")
    w = np.zeros_like(t)
    w[:-1] += 0.5 * h
    w[1:] += 0.5 * h
    return w


def kinked_gain(x: Array, alpha: float, beta: float, eps: float | None) -> tuple[Array, Array]:
    """Return h(x) = beta x + (alpha - beta) max(x, 0) and dh/dx; softplus of width eps when given.

    Args:
        x: Power [W].
        alpha: Slope for x > 0 [-].
        beta: Slope for x < 0 [-].
        eps: Softplus width [W], or None for the exact kink (derivative alpha at x = 0).

    """
    if eps is None:
        return beta * x + (alpha - beta) * np.maximum(x, 0.0), np.where(x >= 0.0, alpha, beta)
    u = x / eps
    soft = eps * np.logaddexp(0.0, u)
    sigmoid = 0.5 * (1.0 + np.tanh(0.5 * u))
    return beta * x + (alpha - beta) * soft, beta + (alpha - beta) * sigmoid


def battery_power(power: ArrayLike, params: BatteryParams, smooth: bool = False) -> tuple[Array, Array, Array, Array]:
    """Return the DC-bus and battery power of per-drive electrical powers, with their derivatives.

    Each drive's power P_i passes its inverter (P_i / eta_inv motoring, P_i eta_inv generating), the
    DC powers add on the bus (one drive's regeneration feeds the others first), and the battery
    delivers P_bus / eta_dis or takes P_bus eta_ch.

    Args:
        power: Motor electrical power P_i [W], shape (..., n): any leading axes (samples, designs).
        params: Efficiencies and smoothing.
        smooth: Softplus kinks of width ``params.smoothing_power`` (the solver's) or exact ones.

    Returns:
        (bus power (...), battery power (...), dP_bat/dP_bus (...), dP_dc,i/dP_i (..., n)) [W, W, -, -].

    """
    p = np.asarray(power, dtype=float)
    eps = params.smoothing_power if smooth else None
    eta = params.inverter_efficiency
    dc, d_dc = kinked_gain(p, 1.0 / eta, eta, eps)
    bus = dc.sum(axis=-1)
    p_bat, d_bat = kinked_gain(bus, 1.0 / params.discharge_efficiency, params.charge_efficiency, eps)
    return bus, p_bat, d_bat, d_dc


def battery_energy(time: ArrayLike, power: ArrayLike, params: BatteryParams, smooth: bool = False) -> BatteryEnergy:
    """Return the battery energy of per-drive electrical powers on a time grid, with its gradient.

    Args:
        time: Strictly increasing sample times [s], shape (K,).
        power: Motor electrical power P_i [W] of each drive, shape (K, n) (n = 3 for the XS 031).
        params: Efficiencies and smoothing.
        smooth: False: exact kinks (the reported value; gradient one-sided at exact zeros).
            True: softplus kinks of width ``params.smoothing_power`` (the solver's value).

    """
    w = trapezoid_weights(time)
    p = np.asarray(power, dtype=float)
    if p.ndim != 2 or p.shape[0] != w.size:
        raise InvalidInputError("power", f"shape {p.shape}", f"must be (K, n) with K = {w.size} time samples")
    bus, p_bat, d_bat, d_dc = battery_power(p, params, smooth)
    eta = params.inverter_efficiency
    dc_exact = kinked_gain(p, 1.0 / eta, eta, None)[0]
    bus_exact = dc_exact.sum(axis=-1)
    return BatteryEnergy(
        energy=float(w @ p_bat),
        gradient=(w * d_bat)[:, None] * d_dc,
        bus_power=bus,
        battery_power=p_bat,
        drawn_energy=w @ np.maximum(p, 0.0),
        net_energy=w @ p,
        dc_bus_drawn_energy=float(w @ np.maximum(bus_exact, 0.0)),
        no_regeneration_energy_at_battery=float(w @ np.maximum(dc_exact, 0.0).sum(axis=1))
        / params.discharge_efficiency,
    )


def rest_battery_energy(rest_energy: ArrayLike, params: BatteryParams) -> tuple[float, float]:
    """Return (battery energy [J], dE_bat / dE_rest,i [-]) of the drives' rest energies E_rest,i [J] >= 0.

    The rest only draws (holding currents, standby, coils), so every drive's inverter and the battery
    are on their motoring branch: E_bat = sum_i E_rest,i / (eta_inv eta_dis).
    """
    e = np.asarray(rest_energy, dtype=float)
    if not np.all(np.isfinite(e)) or np.any(e < 0):
        raise InvalidInputError("rest_energy", e.tolist(), "must be finite and >= 0 (the rest only draws)", "J")
    gain = 1.0 / (params.inverter_efficiency * params.discharge_efficiency)
    return float(e.sum() * gain), gain

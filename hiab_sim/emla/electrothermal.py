"""Hot windings: copper resistance that rises with the winding temperature, and the coupled periodic steady state.

The stator resistance of the data sheet R_s,ref holds at its reference temperature T_ref; at the
winding temperature T [deg C]

    R_s(T) = R_s,ref (1 + alpha (T - T_ref)),            alpha = 0.00393 /K for copper (IEC 60028),

so the copper loss of sample k is P_k = c_k g_k with c_k = 3/2 R_s,ref i_q,k^2 (the loss at T_ref,
:func:`hiab_sim.emla.thermal.copper_loss`) and g_k = 1 + alpha (T_k - T_ref) = beta + alpha theta_k,
theta = T - T_amb, beta = 1 + alpha (T_amb - T_ref). The winding model is that of
:mod:`hiab_sim.emla.thermal` (first order, R_th, tau_th, P linear between samples, exact step):

    theta_{k+1} = e_k theta_k + R_th (u_k P_k + v_k P_{k+1}),   e_k = exp(-h_k/tau), a_k = tau (1 - e_k)/h_k,
                                                                 u_k = a_k - e_k, v_k = 1 - a_k,

and the rest of T_rest after the cycle carries a constant current (a motor holding the last pose;
0 with a brake) whose loss at T_ref is c_r, so during the rest d theta/dt = (R_th c_r g(theta) - theta)/tau,
solved exactly: theta(t) = theta_inf + (theta_{K-1} - theta_inf) exp(-lambda t) with
lambda = (1 - R_th alpha c_r)/tau and theta_inf = R_th beta c_r / (1 - R_th alpha c_r). Periodicity closes
the loop, theta_0 = theta(T_rest).

The fixed point "temperature from the losses, losses from the temperature" is therefore the solution
of the linear system F(theta) = L theta - b = 0 (rows k+1: the step above with P = c g(theta); row 0:
periodicity), solved directly: the loss is affine in theta, so the fixed-point iteration converges in
one Newton step (:attr:`CoupledWinding.fixed_point_change_K` is the change a second step makes, about
1e-12 K, well under the 0.1 K tolerance). A fixed point exists, and attracts, exactly when the
Poincare map theta_0 -> theta_0' has slope rho prod_k (e_k + R_th u_k alpha c_k)/(1 - R_th v_k alpha c_{k+1})
< 1 with rho = exp(-lambda T_rest) and lambda > 0; otherwise, or when the fixed point lies above the
insulation limit, the winding runs away (:attr:`CoupledWinding.runaway`).

Gradients by the implicit function theorem (adjoint): for J = gamma^T theta, L^T mu = gamma and
dJ/dp = -mu^T dF/dp, with dF_{k+1}/dc_k = -R_th u_k g_k, dF_{k+1}/dc_{k+1} = -R_th v_k g_{k+1} and
dF_0/dc_r from rho and theta_inf. The copper energy of the rest is
E_rest = c_r (beta T_rest + alpha int_0^T_rest theta dt), int theta dt = theta_inf T_rest + (theta_{K-1} - theta_inf) q,
q = (1 - rho)/lambda.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_non_negative
from hiab_sim.emla.thermal import Duty, ThermalParams, cycle_time_grid
from hiab_sim.errors import InvalidInputError

#: Temperature coefficient of annealed copper's resistance at 20 deg C [1/K] (IEC 60028: 1/254.5).
COPPER_TEMPERATURE_COEFFICIENT = 0.00393

#: Largest change [K] a further fixed-point step may make (the brief's convergence tolerance).
FIXED_POINT_TOLERANCE_K = 0.1


@dataclass(frozen=True)
class WindingResistance:
    """Temperature dependence of one motor's stator resistance.

    Attributes:
        reference_temperature: T_ref [deg C] at which the data sheet gives R_s (finite).
        temperature_coefficient: alpha [1/K] >= 0 (0.00393 for copper; 0 keeps R_s constant).
        insulation_limit: Temperature [deg C] of the insulation class, > T_ref: a fixed point above it
            counts as thermal runaway.
        label: Prefix of error messages (e.g. ``lift.winding_resistance``).

    """

    reference_temperature: float
    temperature_coefficient: float
    insulation_limit: float
    label: str = "winding_resistance"

    def __post_init__(self) -> None:
        if not math.isfinite(self.reference_temperature):
            raise InvalidInputError(f"{self.label}.reference_temperature", self.reference_temperature, "must be finite")
        check_non_negative(f"{self.label}.temperature_coefficient", self.temperature_coefficient, "1/K")
        if not (math.isfinite(self.insulation_limit) and self.insulation_limit > self.reference_temperature):
            raise InvalidInputError(
                f"{self.label}.insulation_limit",
                self.insulation_limit,
                f"must be finite and > reference_temperature = {self.reference_temperature:g} deg C",
                "deg C",
            )

    def factor(self, temperature: ArrayLike) -> Array:
        """R_s(T) / R_s,ref = 1 + alpha (T - T_ref) [-] at temperatures [deg C]."""
        t = np.asarray(temperature, dtype=float)
        return np.asarray(1.0 + self.temperature_coefficient * (t - self.reference_temperature))


@dataclass(frozen=True)
class CoupledWinding:
    """Periodic steady state of a winding whose copper loss rises with its temperature.

    Attributes:
        temperature: T_k [deg C] at the cycle's samples, shape (K,) (NaN when ``runaway``).
        resistance_factor: g_k = R_s(T_k)/R_s,ref [-], shape (K,).
        hot_loss: P_k = c_k g_k [W], shape (K,).
        rest_energy: Copper energy of the rest at the rest's temperatures [J].
        peak: Largest sample temperature [deg C] (the rest is monotone, so it is a sample).
        peak_index: Its index.
        poincare_slope: Slope of the one-period map theta_0 -> theta_0' [-]; a fixed point needs < 1.
        runaway: True when no fixed point exists below the insulation limit.
        fixed_point_change_K: Largest change [K] one more fixed-point step makes at the solution.

    """

    temperature: Array
    resistance_factor: Array
    hot_loss: Array
    rest_energy: float
    peak: float
    peak_index: int
    poincare_slope: float
    runaway: bool
    fixed_point_change_K: float
    _system: _System = field(repr=False)

    def loss_gradient(
        self, weights: ArrayLike, rest_weight: float = 0.0, theta_weights: ArrayLike | None = None
    ) -> tuple[Array, float]:
        """Gradient of J = sum_k y_k P_k + z E_rest + sum_k x_k T_k w.r.t. the cold losses (c_k, c_r).

        Args:
            weights: y_k, shape (K,) (e.g. trapezoid weights [s] for the cycle's copper energy).
            rest_weight: z [-] multiplying the rest's copper energy.
            theta_weights: x_k, shape (K,), a further linear term in the temperatures (None: 0).

        Returns:
            (dJ/dc, shape (K,), dJ/dc_r), with theta's dependence on (c, c_r) through the adjoint.

        """
        s = self._system
        y = np.asarray(weights, dtype=float)
        alpha = s.alpha
        g = self.resistance_factor
        gamma = y * s.c * alpha
        gamma[-1] += rest_weight * s.c_r * alpha * s.q
        if theta_weights is not None:
            gamma = gamma + np.asarray(theta_weights, dtype=float)
        d_c, d_cr = s.adjoint(gamma, g)
        d_c = d_c + y * g
        d_cr = d_cr + rest_weight * s.rest_energy_partial_cr
        return d_c, d_cr

    def temperature_gradient(self, index: int) -> tuple[Array, float]:
        """(d T_index / d c_k [K/W], shape (K,), d T_index / d c_r [K/W])."""
        s = self._system
        if not 0 <= index < s.c.size:
            raise InvalidInputError("index", index, f"must be in [0, {s.c.size - 1}]")
        gamma = np.zeros_like(s.c)
        gamma[index] = 1.0
        return s.adjoint(gamma, self.resistance_factor)


@dataclass(frozen=True)
class _System:
    """The linear system L theta = b of the module docstring and what its derivatives need."""

    c: Array
    c_r: float
    alpha: float
    r_th: float
    u: Array
    v: Array
    lower: Array  # L itself, (K, K)
    rho_prime: float  # d rho / d c_r
    sigma_prime: float  # d sigma / d c_r
    theta_end: float  # theta_{K-1}
    q: float  # (1 - rho) / lambda [s]
    rest_energy_partial_cr: float  # explicit d E_rest / d c_r at fixed theta_{K-1} [-]

    def adjoint(self, gamma: Array, g: Array) -> tuple[Array, float]:
        """(dJ/dc, dJ/dc_r) of J = gamma^T theta through L^T mu = gamma and -mu^T dF/dp."""
        mu = np.linalg.solve(self.lower.T, gamma)
        d_c = np.zeros_like(self.c)
        d_c[:-1] += mu[1:] * self.r_th * self.u * g[:-1]
        d_c[1:] += mu[1:] * self.r_th * self.v * g[1:]
        d_cr = float(mu[0] * (self.rho_prime * self.theta_end + self.sigma_prime))
        return d_c, d_cr


def coupled_winding_temperature(
    time: ArrayLike,
    cold_loss: ArrayLike,
    thermal: ThermalParams,
    winding: WindingResistance | None,
    duty: Duty,
    rest_cold_loss: float = 0.0,
) -> CoupledWinding:
    """Return the periodic steady state of the winding with R_s(T) (see the module docstring).

    Args:
        time: Cycle sample times [s], shape (K,), spanning ``duty.cycle_time``.
        cold_loss: c_k, the copper loss at the reference temperature [W], shape (K,), >= 0.
        thermal: The motor's first-order thermal model.
        winding: R_s(T) data (reference temperature, coefficient, insulation limit); None keeps R_s at
            its reference value (alpha = 0, beta = 1: the cold model, never runaway).
        duty: Cycle and rest time.
        rest_cold_loss: c_r [W] >= 0, the rest's copper loss at the reference temperature.

    """
    t = cycle_time_grid(time, duty)
    c = np.asarray(cold_loss, dtype=float)
    if c.shape != t.shape:
        raise InvalidInputError("cold_loss", f"shape {c.shape}", f"must be ({t.size},)")
    check_non_negative("rest_cold_loss", rest_cold_loss, "W")
    tau, r = thermal.time_constant, thermal.thermal_resistance
    alpha = 0.0 if winding is None else winding.temperature_coefficient
    beta = 1.0 if winding is None else 1.0 + alpha * (thermal.ambient_temperature - winding.reference_temperature)
    limit = math.inf if winding is None else winding.insulation_limit
    h = np.diff(t)
    e = np.exp(-h / tau)
    a = tau * (-np.expm1(-h / tau)) / h
    u, v = a - e, 1.0 - a
    K = t.size
    sub = e + r * u * alpha * c[:-1]
    diag = 1.0 - r * v * alpha * c[1:]
    # rest: lambda, rho, theta_inf and their c_r derivatives
    c_r, t_r = float(rest_cold_loss), duty.rest_time
    denom = 1.0 - r * alpha * c_r
    lam = denom / tau
    runaway_rest = t_r > 0 and lam <= 0
    if runaway_rest or np.any(diag <= 0):
        return _runaway(K, c, c_r, alpha, r, u, v)
    rho = math.exp(-lam * t_r)
    theta_inf = r * beta * c_r / denom
    sigma = theta_inf * (1.0 - rho)
    slope = rho * float(np.prod(sub / diag))
    if slope >= 1.0:
        return _runaway(K, c, c_r, alpha, r, u, v, slope)
    lower = np.zeros((K, K))
    lower[0, 0] = 1.0
    lower[0, -1] -= rho
    idx = np.arange(K - 1)
    lower[idx + 1, idx + 1] = diag
    lower[idx + 1, idx] = -sub
    b = np.empty(K)
    b[0] = sigma
    b[1:] = r * beta * (u * c[:-1] + v * c[1:])
    theta: Array = np.asarray(np.linalg.solve(lower, b), dtype=float)
    g: Array = np.asarray(beta + alpha * theta, dtype=float)
    # one more fixed-point step: losses from this temperature, temperature from those losses
    change = float(np.max(np.abs(_step_once(theta, c, g, e, u, v, r, rho, theta_inf) - theta)))
    theta_end = float(theta[-1])
    q = t_r if lam * t_r < 1e-12 else -math.expm1(-lam * t_r) / lam
    integral = theta_inf * t_r + (theta_end - theta_inf) * q
    rest_energy = c_r * (beta * t_r + alpha * integral)
    d_lam = -r * alpha / tau
    rho_p = -t_r * rho * d_lam
    theta_inf_p = r * beta / denom**2
    sigma_p = theta_inf_p * (1.0 - rho) - theta_inf * rho_p
    q_p = 0.0 if lam * t_r < 1e-12 else (-rho_p * lam - (1.0 - rho) * d_lam) / lam**2
    integral_p = theta_inf_p * (t_r - q) + (theta_end - theta_inf) * q_p
    temp: Array = np.asarray(thermal.ambient_temperature + theta, dtype=float)
    j = int(np.argmax(theta))
    return CoupledWinding(
        temperature=temp,
        resistance_factor=g,
        hot_loss=c * g,
        rest_energy=rest_energy,
        peak=float(temp[j]),
        peak_index=j,
        poincare_slope=slope,
        runaway=bool(temp[j] > limit),
        fixed_point_change_K=change,
        _system=_System(
            c=c,
            c_r=c_r,
            alpha=alpha,
            r_th=r,
            u=u,
            v=v,
            lower=lower,
            rho_prime=rho_p,
            sigma_prime=sigma_p,
            theta_end=theta_end,
            q=q,
            rest_energy_partial_cr=beta * t_r + alpha * integral + c_r * alpha * integral_p,
        ),
    )


def _step_once(
    theta: Array, c: Array, g: Array, e: Array, u: Array, v: Array, r: float, rho: float, theta_inf: float
) -> Array:
    """Temperatures [K above ambient] that the losses c g(theta) give over one period from theta's rest end."""
    p = c * g
    out = np.empty_like(theta)
    out[0] = theta_inf + (theta[-1] - theta_inf) * rho
    for k in range(theta.size - 1):
        out[k + 1] = e[k] * out[k] + r * (u[k] * p[k] + v[k] * p[k + 1])
    return out


def _runaway(
    K: int, c: Array, c_r: float, alpha: float, r: float, u: Array, v: Array, slope: float = math.inf
) -> CoupledWinding:
    """The state reported when no fixed point exists: NaN temperatures, infinite peak."""
    nan = np.full(K, np.nan)
    return CoupledWinding(
        temperature=nan,
        resistance_factor=nan,
        hot_loss=nan,
        rest_energy=math.inf,
        peak=math.inf,
        peak_index=0,
        poincare_slope=slope,
        runaway=True,
        fixed_point_change_K=math.nan,
        _system=_System(c, c_r, alpha, r, u, v, np.eye(K), 0.0, 0.0, math.nan, math.nan, math.nan),
    )

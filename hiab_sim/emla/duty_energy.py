"""One EMLA over a whole duty period: hot windings, the hold during the rest, energy, RMS torque and temperature.

Composes :mod:`hiab_sim.emla.drive` (cycle samples), :mod:`hiab_sim.emla.hold` (the rest) and
:mod:`hiab_sim.emla.electrothermal` (R_s at the winding temperature) for the duty of
:class:`DutyOptions`: the cycle of duration T on the samples, then a rest of T_rest, repeated.

Per sample k (powers at the drive's electrical input, the DC side when the inverter loss is modelled):

    P_k = P_k,ref + (g_k - 1) c_k + P_coil,cycle

with P_k,ref the drive power at R_s,ref (:func:`hiab_sim.emla.electrical_power`), c_k = s_k 3/2 R_s,ref i_q,k^2
the copper loss at R_s,ref (s the brake release factor), g_k = R_s(T_k)/R_s,ref at the coupled periodic
winding temperature (1 without ``hot`` or without winding data) and P_coil,cycle the holding brake's
coil while released when no sample-by-sample brake model counts it. The rest adds at the drive

    E_rest = E_cu,rest + P_other T_rest + g_0 E_tr,first + g_{K-1} E_tr,last + E_tr,other

(:class:`hiab_sim.emla.hold.RestHold`; E_cu,rest = c_r T_rest cold, or the hot rest energy of
:class:`~hiab_sim.emla.electrothermal.CoupledWinding`). RMS torque over the period:
tau_rms^2 = (int (s tau_m)^2 dt + tau_r^2 T_rest) / P with tau_r the rest's motor torque.

Gradients of J = sum_k y_k P_k + z E_rest, of tau_rms and of the peak temperature w.r.t. the load
samples (f_x, v_x, a_x) are exact for the smooth model (``exact=False``): the temperature's
dependence on every sample comes from the adjoint of the coupled winding model, the rest's from
the first and last samples' forces.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_choice
from hiab_sim.emla.config import EmlaParams
from hiab_sim.emla.drive import broadcast_inputs, drive_state
from hiab_sim.emla.electrothermal import CoupledWinding, coupled_winding_temperature
from hiab_sim.emla.hold import HOLD_MODES, RestHold, rest_hold
from hiab_sim.emla.losses import brake_release
from hiab_sim.emla.model import electrical_power_partials, state_power, state_power_partials
from hiab_sim.emla.thermal import Duty, cycle_time_grid


@dataclass(frozen=True)
class DutyOptions:
    """How the duty period is modelled.

    Attributes:
        duty: Cycle and rest time.
        hold: ``brake`` or ``motor`` (:mod:`hiab_sim.emla.hold`), or None: the rest costs nothing and
            carries no torque (the seed paper's and the earlier thermal model).
        hot: R_s at the coupled winding temperature for drives with winding and thermal data.

    """

    duty: Duty
    hold: str | None = None
    hot: bool = False

    def __post_init__(self) -> None:
        if self.hold is not None:
            check_choice("duty.hold", self.hold, HOLD_MODES)


@dataclass(frozen=True)
class DriveDuty:
    """One EMLA over the duty period (see the module docstring); arrays of shape (K,).

    Attributes:
        power: P_k [W] with hot windings and the cycle's coil power.
        reference_power: P_k,ref [W], the drive power at R_s,ref.
        copper_loss_ref: c_k [W].
        rest_energy: E_rest [J] at the drive.
        rest_copper_energy: Its copper part [J].
        rms_torque: tau_rms over the period [N m] (NaN without thermal data).
        peak_temperature: Peak periodic winding temperature [deg C] (NaN without thermal data, inf on runaway).
        runaway: No fixed point below the insulation limit.
        winding: The coupled winding state (None without thermal data).
        hold: The rest (None when ``hold`` is None).

    """

    power: Array
    reference_power: Array
    copper_loss_ref: Array
    rest_energy: float
    rest_copper_energy: float
    rms_torque: float
    peak_temperature: float
    runaway: bool
    winding: CoupledWinding | None
    hold: RestHold | None
    _parts: _Parts
    #: rms_partials and peak_partials once computed (read-only arrays): the NLP's rows ask for them at a
    #: point's values and again for its Jacobian, and each peak costs a (K, K) adjoint solve
    _memo: dict[str, Array] = field(default_factory=dict, compare=False, repr=False)

    def _memoised(self, key: str, compute: Callable[[], Array]) -> Array:
        if key not in self._memo:
            value = compute()
            value.setflags(write=False)
            self._memo[key] = value
        return self._memo[key]

    def energy_partials(self, weights: ArrayLike, rest_weight: float) -> tuple[Array, Array, Array]:
        """d(sum_k y_k P_k + z E_rest) / d(f_x, v_x, a_x)_k, each shape (K,) [m/s, N, kg m/s for y in s]."""
        p = self._parts
        y = np.asarray(weights, dtype=float)
        z = float(rest_weight)
        dp = [y * d for d in p.power_ref_partials]
        hold = self.hold
        w = self.winding
        K = y.size
        extra_c = np.zeros(K)
        d_cr = z * p.duty.rest_time  # cold rest: E_cu,rest = c_r T_rest
        tr = (0.0, 0.0) if hold is None else hold.transition_copper_ref
        if w is not None and p.hot:
            theta_w = np.zeros(K)
            theta_w[0] += z * p.alpha * tr[0]
            theta_w[-1] += z * p.alpha * tr[1]
            d_c, d_cr = w.loss_gradient(y, z, theta_w)
            extra_c = d_c - y  # the cold part y_k dc_k is in P_k,ref's partials already
        g0, g1 = (p.g[0], p.g[-1])
        for j in range(3):
            dp[j] = dp[j] + extra_c * p.copper_partials[j]
        if hold is not None:
            d_first = z * (g0 * hold.d_transition_copper_ref[0] + hold.d_transition_other_energy[0])
            d_last = z * (
                g1 * hold.d_transition_copper_ref[1]
                + hold.d_transition_other_energy[1]
                + hold.d_rest_other_power * p.duty.rest_time
            )
            d_last += d_cr * hold.d_rest_copper_loss_ref
            dp[0][0] += d_first
            dp[0][-1] += d_last
        return dp[0], dp[1], dp[2]

    def rms_partials(self) -> Array:
        """D tau_rms / d(f_x, v_x, a_x)_k, shape (3, K) (computed once, read-only)."""
        return self._memoised("rms", self._rms_partials)

    def peak_partials(self) -> Array:
        """D T_peak / d(f_x, v_x, a_x)_k, shape (3, K), computed once, read-only.

        The peak sample is held; zeros without thermal data.
        """
        return self._memoised("peak", self._peak_partials)

    def _rms_partials(self) -> Array:
        p = self._parts
        rms = self.rms_torque
        out = np.zeros((3, p.tau.size))
        if not rms > 0:
            return out
        base = p.w * p.tau / (p.duty.period * rms)
        for j in range(3):
            out[j] = base * p.tau_partials[j]
        if self.hold is not None and self.hold.rest_torque != 0.0:
            out[0, -1] += self.hold.rest_torque * p.duty.rest_time / (p.duty.period * rms) / p.k
        return out

    def _peak_partials(self) -> Array:
        p = self._parts
        out = np.zeros((3, p.tau.size))
        if self.winding is None or not math.isfinite(self.winding.peak):
            return out  # no fixed point at all (a fixed point above the insulation limit keeps its partials)
        d_c, d_cr = self.winding.temperature_gradient(self.winding.peak_index)
        for j in range(3):
            out[j] = d_c * p.copper_partials[j]
        if self.hold is not None:
            out[0, -1] += d_cr * self.hold.d_rest_copper_loss_ref
        return out


@dataclass(frozen=True)
class _Parts:
    """What the partials need."""

    duty: Duty
    hot: bool
    alpha: float
    k: float
    g: Array
    w: Array
    tau: Array
    tau_partials: tuple[Array, Array, Array]
    copper_partials: tuple[Array, Array, Array]
    power_ref_partials: tuple[Array, Array, Array]


def drive_duty(
    params: EmlaParams,
    time: ArrayLike,
    force: ArrayLike,
    velocity: ArrayLike,
    acceleration: ArrayLike,
    options: DutyOptions,
    exact: bool = False,
) -> DriveDuty:
    """Return one EMLA's powers, rest energy, RMS torque and winding temperature over the duty period.

    Args:
        params: The actuator.
        time: Cycle sample times [s], shape (K,), spanning ``options.duty.cycle_time``.
        force: Load force f_x [N], shape (K,).
        velocity: Rod velocity v_x [m/s], shape (K,).
        acceleration: Rod acceleration a_x [m/s^2], shape (K,).
        options: Duty, hold and hot windings.
        exact: Exact brake switching and loss kinks (values; partials are the smooth model's).

    """
    duty = options.duty
    t = np.asarray(time, dtype=float)
    cycle_time_grid(t, duty)
    f, v, a = broadcast_inputs(force, velocity, acceleration)
    st = drive_state(params, f, v, a, exact)
    s, ds = brake_release(params.losses, v, exact)
    m = params.motor
    cc = 1.5 * m.stator_resistance / m.torque_constant**2
    c = s * cc * st.motor_torque**2
    dc = [s * 2.0 * cc * st.motor_torque * d for d in st.d_motor_torque]
    dc[1] = dc[1] + ds * cc * st.motor_torque**2
    tau = s * st.motor_torque
    d_tau = [s * d for d in st.d_motor_torque]
    d_tau[1] = d_tau[1] + ds * st.motor_torque
    p_ref = state_power(params, st, v, exact)
    hold = rest_hold(params, options.hold, float(f[0]), float(f[-1]), duty.cycle_time) if options.hold else None
    c_r = hold.rest_copper_loss_ref if hold is not None else 0.0
    hot = options.hot and params.winding is not None and params.thermal is not None
    winding = None
    g = np.ones_like(c)
    rest_cu = c_r * duty.rest_time
    if params.thermal is not None:
        winding = coupled_winding_temperature(t, c, params.thermal, params.winding if hot else None, duty, c_r)
        if hot:
            g = winding.resistance_factor
            rest_cu = winding.rest_energy
    coil = 0.0 if hold is None else hold.cycle_coil_energy / duty.cycle_time
    power = p_ref + (g - 1.0) * c + coil
    rest = rest_cu
    if hold is not None:
        tr = hold.transition_copper_ref
        rest += hold.rest_other_power * duty.rest_time + g[0] * tr[0] + g[-1] * tr[1] + hold.transition_other_energy
    w = np.zeros_like(t)
    h = np.diff(t)
    w[:-1] += 0.5 * h
    w[1:] += 0.5 * h
    tau_r = hold.rest_torque if hold is not None else 0.0
    rms = math.sqrt((float(w @ tau**2) + tau_r**2 * duty.rest_time) / duty.period) if params.thermal else math.nan
    peak = math.nan if winding is None else winding.peak
    pf, pv, pa = electrical_power_partials(params, f, v, a) if exact else state_power_partials(params, st, v)
    return DriveDuty(
        power=power,
        reference_power=p_ref,
        copper_loss_ref=c,
        rest_energy=rest,
        rest_copper_energy=rest_cu,
        rms_torque=rms,
        peak_temperature=peak,
        runaway=bool(winding is not None and winding.runaway),
        winding=winding,
        hold=hold,
        _parts=_Parts(
            duty=duty,
            hot=hot,
            alpha=params.winding.temperature_coefficient if hot and params.winding is not None else 0.0,
            k=params.transmission_ratio,
            g=g,
            w=w,
            tau=tau,
            tau_partials=(d_tau[0], d_tau[1], d_tau[2]),
            copper_partials=(dc[0], dc[1], dc[2]),
            power_ref_partials=(pf, pv, pa),
        ),
    )

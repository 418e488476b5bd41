"""The hydraulic baselines at the battery, the EMLAs' boundary: valve-controlled with counterbalance valves, and EHAs.

Every figure here is energy *taken from the battery* over the cycle [J], as the EMLAs' battery energy
(:mod:`hiab_sim.emla.battery`), with every loss on the way named. Per cylinder i and sample k (rod force
f_x [N], velocity v_x [m/s] from the inverse dynamics, eq. ``dynamics``), with the seal friction of the
crane file f_h = f_x + b v_x + F_c sign(v_x) and F_m = f_h sign(v_x), the force the fluid must deliver in
the direction of motion (> 0 resistive, < 0 overrunning):

Valve-controlled (``constant_pressure``, ``load_sensing``): one pump, driven by an electric motor
through an inverter from the battery. The meter-in chamber (area A_in) takes Q = A_in |v_x| at p_in, the
other (A_out) returns to tank, unless a counterbalance valve
(:class:`~hiab_sim.hydraulics.cylinders.CounterbalanceValve`) sits in its outlet: it opens when
p_out + R p_in = p_set, so with the piston's balance p_in A_in - p_out A_out = F_m

    p_in = (F_m + p_set A_out) / (A_in + R A_out),  p_out = p_set - R p_in

(fully open, p_out = 0 and p_in = F_m / A_in, once p_in > p_set / R; p_in = 0 and p_out = -F_m / A_out if
the load alone exceeds the setting). The valve dissipates p_out A_out |v_x|: the load's returned power
and the pilot pressure's work. Without a valve in the outlet an overrunning load gets p_in = 0 and the
directional valve's meter-out edge dissipates -F_m |v_x|. Flow into a valve-held chamber passes its check
(loss p_check Q). Pump pressure: p_s (constant pressure) or max_i p_in,i + Delta p_LS over the moving
cylinders (load sensing). Pump flow Q_p = sum_i Q_i + G_leak p_p (valve and cylinder leakage, laminar)
+ Q_bleed (load sensing: the LS line's bleed). Then P_shaft = p_p Q_p / eta_pump, P_motor = P_shaft /
eta_motor, P_dc = P_motor / eta_inv and P_bat = P_dc / eta_dis (the pump only draws).

Pump-controlled (``pump_controlled``, an electro-hydraulic actuator per cylinder, as HIAB's EHLA): each
cylinder has its own reversible pump and servo motor on the shared DC bus; the pump moves the load-side
chamber's flow at the load pressure (charge pressure 0), so its hydraulic power is exactly f_h v_x, four
quadrant: P_shaft = P_h / eta_p motoring, P_h eta_p when the load drives it; P_el likewise through
eta_m; the inverters and the battery as the EMLAs' (:func:`hiab_sim.emla.battery.battery_power`:
regeneration of one drive feeds the others first).

Energy balance (each term by the trapezoid rule): ``battery_energy`` = sum of ``terms`` (useful work
int f_x v_x dt, negative where the loads return energy, and every loss), to round-off.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.checks import check_efficiency, check_non_negative, check_positive
from hiab_sim.emla.battery import BatteryParams, battery_power, trapezoid_weights
from hiab_sim.errors import InvalidInputError
from hiab_sim.hydraulics.cylinders import HydraulicSystem

#: The variants at the battery, in the order :func:`battery_boundary_baselines` returns them.
BOUNDARY_VARIANTS: tuple[str, ...] = ("constant_pressure", "load_sensing", "pump_controlled")


@dataclass(frozen=True)
class CircuitParams:
    """Pump, drive and leakage data of the hydraulic baselines at the battery (stated constants).

    Attributes:
        load_sensing_margin: Delta p_LS [Pa] > 0 (estimate: 2.0 MPa, mobile LS valves use 1.5-3 MPa).
        pump_efficiency: Overall efficiency of the variable piston pump (estimate: 0.85).
        motor_efficiency: Its electric motor (estimate: 0.92, an IE3 motor of about 10 kW).
        inverter_efficiency: Its inverter (estimate: 0.97, the EMLA paper preset's value).
        leakage_conductance: G_leak [m^3/(s Pa)] >= 0 (estimate: three valve sections leaking 20 cm^3/min
            each at 10 MPa, 1.0e-13).
        bleed_flow: Q_bleed [m^3/s] >= 0 of the load-sensing pump's LS line (estimate: 0.5 L/min).
        eha_pump_efficiency: Reversible pump of an EHA, both directions (estimate: 0.85).
        eha_motor_efficiency: Its servo motor, both directions (estimate: 0.92).
        standstill_speed: |v_x| [m/s] >= 0 below which a valve-controlled cylinder is held closed.
        supply_pressure: p_s [Pa] override, or None for the crane file's.

    """

    load_sensing_margin: float = 2.0e6
    pump_efficiency: float = 0.85
    motor_efficiency: float = 0.92
    inverter_efficiency: float = 0.97
    leakage_conductance: float = 1.0e-13
    bleed_flow: float = 0.5e-3 / 60.0
    eha_pump_efficiency: float = 0.85
    eha_motor_efficiency: float = 0.92
    standstill_speed: float = 1.0e-3
    supply_pressure: float | None = None

    def __post_init__(self) -> None:
        check_positive("hydraulics.load_sensing_margin", self.load_sensing_margin, "Pa")
        for key in ("pump_efficiency", "motor_efficiency", "inverter_efficiency"):
            check_efficiency(f"hydraulics.{key}", getattr(self, key))
        check_efficiency("hydraulics.eha_pump_efficiency", self.eha_pump_efficiency)
        check_efficiency("hydraulics.eha_motor_efficiency", self.eha_motor_efficiency)
        check_non_negative("hydraulics.leakage_conductance", self.leakage_conductance, "m^3/(s Pa)")
        check_non_negative("hydraulics.bleed_flow", self.bleed_flow, "m^3/s")
        check_non_negative("hydraulics.standstill_speed", self.standstill_speed, "m/s")
        if self.supply_pressure is not None:
            check_positive("hydraulics.supply_pressure", self.supply_pressure, "Pa")


@dataclass(frozen=True)
class BoundaryResult:
    """One hydraulic variant over the cycle, at the battery.

    Attributes:
        variant: One of :data:`BOUNDARY_VARIANTS`.
        battery_energy: Energy taken from the battery [J] (the EMLAs' boundary).
        battery_power: P_bat [W], shape (K,).
        terms: Energies [J] summing to ``battery_energy``: ``useful_work`` and the losses.
        max_pilot_pressure: Largest counterbalance pilot pressure the pump had to supply [Pa].
        pressure_shortfall_samples: Samples where a cylinder needs more than p_s (constant pressure).

    """

    variant: str
    battery_energy: float
    battery_power: Array
    terms: dict[str, float]
    max_pilot_pressure: float = 0.0
    pressure_shortfall_samples: int = 0

    @property
    def balance_residual(self) -> float:
        """battery_energy - sum(terms) [J] (round-off)."""
        return self.battery_energy - math.fsum(self.terms.values())


def _chambers(force: Array, velocity: Array, cylinders: HydraulicSystem, standstill: float) -> dict[str, Array]:
    """Per-sample chamber pressures, flows and valve losses of each cylinder (module docstring), (K, n) each."""
    cyl = tuple(cylinders)
    moving = np.abs(velocity) >= standstill
    v = np.where(moving, velocity, 0.0)
    friction = cylinders.viscous_friction * v + cylinders.coulomb_friction * np.sign(v)
    f_h = force + friction
    speed = np.abs(v)
    ext = v > 0
    a_p = np.array([c.piston_area for c in cyl])
    a_r = np.array([c.annulus_area for c in cyl])
    a_in, a_out = np.where(ext, a_p, a_r), np.where(ext, a_r, a_p)
    f_m = f_h * np.sign(v)
    p_in = np.where(f_m > 0, f_m / a_in, 0.0)
    p_out = np.zeros_like(p_in)
    meter_out = np.where(f_m < 0, -f_m * speed, 0.0)
    check = np.zeros_like(p_in)
    pilot = np.zeros_like(p_in)
    for i, c in enumerate(cyl):
        cb = c.counterbalance
        if cb is None:
            continue
        out_of_held = ~ext[:, i] if cb.side == "piston" else ext[:, i]
        held_out = out_of_held & moving[:, i]  # flow leaves the valve-held chamber
        held_in = ~out_of_held & moving[:, i]
        r, ps = cb.pilot_ratio, cb.setting_pressure
        ai, ao, fm = a_in[:, i], a_out[:, i], f_m[:, i]
        pin = (fm + ps * ao) / (ai + r * ao)
        pout = ps - r * pin
        open_full = pout < 0
        pin = np.where(open_full, fm / ai, pin)
        pout = np.where(open_full, 0.0, pout)
        by_load = pin < 0
        pout = np.where(by_load, -fm / ao, pout)
        pin = np.where(by_load, 0.0, pin)
        p_in[:, i] = np.where(held_out, pin, p_in[:, i])
        p_out[:, i] = np.where(held_out, pout, 0.0)
        pilot[:, i] = np.where(held_out & (fm < 0), pin, 0.0)
        meter_out[:, i] = np.where(held_out, 0.0, meter_out[:, i])
        p_in[:, i] = np.where(held_in, p_in[:, i] + cb.check_pressure, p_in[:, i])
        check[:, i] = np.where(held_in, cb.check_pressure * ai * speed[:, i], 0.0)
    flow = a_in * speed
    return {
        "moving": moving.astype(float),
        "velocity": v,
        "fluid_power": f_h * v,
        "useful": force * v,
        "friction": friction * v,
        "p_in": p_in,
        "flow": flow,
        "counterbalance": p_out * a_out * speed,
        "meter_out": meter_out,
        "check": check,
        "pilot": pilot,
    }


def _valve_variant(
    variant: str, w: Array, ch: dict[str, Array], p_s: float, circuit: CircuitParams, battery: BatteryParams
) -> BoundaryResult:
    moving = ch["moving"] > 0
    if variant == "constant_pressure":
        p_pump = np.full(w.size, p_s)
        bleed = 0.0
    else:
        p_pump = np.where(moving, ch["p_in"], 0.0).max(axis=1) + circuit.load_sensing_margin
        bleed = circuit.bleed_flow
    q_cyl = ch["flow"].sum(axis=1)
    leak = circuit.leakage_conductance * p_pump
    hyd = p_pump * (q_cyl + leak + bleed)
    shaft = hyd / circuit.pump_efficiency
    motor = shaft / circuit.motor_efficiency
    dc = motor / circuit.inverter_efficiency
    p_bat = dc / battery.discharge_efficiency

    def e(x: Array) -> float:
        return float(w @ x)

    terms = {
        "useful_work": e(ch["useful"].sum(axis=1)),
        "cylinder_friction": e(ch["friction"].sum(axis=1)),
        "meter_in_throttling": e(((p_pump[:, None] - ch["p_in"]) * ch["flow"]).sum(axis=1)),
        "meter_out_throttling": e(ch["meter_out"].sum(axis=1)),
        "counterbalance_valves": e(ch["counterbalance"].sum(axis=1)),
        "check_valves": e(ch["check"].sum(axis=1)),
        "leakage": e(p_pump * leak),
        "load_sensing_bleed": e(p_pump * bleed),
        "pump": e(shaft - hyd),
        "pump_motor": e(motor - shaft),
        "inverter": e(dc - motor),
        "battery": e(p_bat - dc),
    }
    shortfall = int(np.count_nonzero(np.any(ch["p_in"] > p_pump[:, None] + 1e-9, axis=1)))
    return BoundaryResult(variant, e(p_bat), p_bat, terms, float(ch["pilot"].max()), shortfall)


def _eha_variant(w: Array, ch: dict[str, Array], circuit: CircuitParams, battery: BatteryParams) -> BoundaryResult:
    p_h = ch["fluid_power"]
    eta_p, eta_m = circuit.eha_pump_efficiency, circuit.eha_motor_efficiency
    shaft = np.where(p_h > 0, p_h / eta_p, p_h * eta_p)
    elec = np.where(shaft > 0, shaft / eta_m, shaft * eta_m)
    params = BatteryParams(
        inverter_efficiency=circuit.inverter_efficiency,
        discharge_efficiency=battery.discharge_efficiency,
        charge_efficiency=battery.charge_efficiency,
        smoothing_power=battery.smoothing_power,
    )
    bus, p_bat, _, _ = battery_power(elec, params)
    eta = circuit.inverter_efficiency
    dc = np.where(elec > 0, elec / eta, elec * eta)

    def e(x: Array) -> float:
        return float(w @ x)

    terms = {
        "useful_work": e(ch["useful"].sum(axis=1)),
        "cylinder_friction": e(ch["friction"].sum(axis=1)),
        "pump": e((shaft - p_h).sum(axis=1)),
        "pump_motor": e((elec - shaft).sum(axis=1)),
        "inverter": e((dc - elec).sum(axis=1)),
        "battery": e(p_bat - bus),
    }
    return BoundaryResult("pump_controlled", e(p_bat), p_bat, terms)


def battery_boundary_baselines(
    time: ArrayLike,
    force: ArrayLike,
    velocity: ArrayLike,
    cylinders: HydraulicSystem,
    battery: BatteryParams,
    circuit: CircuitParams | None = None,
) -> tuple[BoundaryResult, BoundaryResult, BoundaryResult]:
    """Return the (constant-pressure, load-sensing, pump-controlled) baselines at the battery.

    Args:
        time: Strictly increasing sample times [s], shape (K,).
        force: Rod force f_x [N], shape (K, n), columns in the cylinders' order.
        velocity: Rod velocity v_x [m/s], shape (K, n).
        cylinders: The crane's cylinders, with their counterbalance valves.
        battery: The battery (discharge and charge efficiencies of the EMLA file's battery section).
        circuit: Pump, drive and leakage data (defaults when None).

    """
    circuit = CircuitParams() if circuit is None else circuit
    w = trapezoid_weights(time)
    f, v = (np.asarray(x, dtype=float) for x in (force, velocity))
    n = len(tuple(cylinders))
    if f.shape != (w.size, n) or v.shape != f.shape:
        raise InvalidInputError("force, velocity", f"shapes {f.shape}, {v.shape}", f"must both be ({w.size}, {n})")
    ch = _chambers(f, v, cylinders, circuit.standstill_speed)
    eha = _chambers(f, v, cylinders, 0.0)  # a pump-controlled cylinder has no closed valve: it follows any speed
    p_s = cylinders.supply_pressure if circuit.supply_pressure is None else circuit.supply_pressure
    return (
        _valve_variant("constant_pressure", w, ch, p_s, circuit, battery),
        _valve_variant("load_sensing", w, ch, p_s, circuit, battery),
        _eha_variant(w, eha, circuit, battery),
    )

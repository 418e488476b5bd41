"""Energy the crane's valve-controlled hydraulic cylinders draw for the same motion and loads as the EMLAs.

Per cylinder i and sample k, from the rod force f_x [N] (positive pushing) and rod velocity v_x
[m/s] (positive extending) that the inverse dynamics gives each actuator (eq. ``dynamics``):

* Force the fluid must supply, with the cylinder's own seal friction (crane YAML):
  f_h = f_x + b v_x + F_c sign(v_x).
* Meter-in chamber and flow from the pump: extending, the piston side, Q = A_p v_x; retracting,
  the rod side, Q = A_r |v_x| (A_p = pi D^2/4, A_r = pi (D^2 - d^2)/4). The other chamber returns
  to tank.
* Four quadrants. Resistive load (f_h v_x > 0, the fluid does the work): the meter-in chamber
  needs the load pressure p_L = |f_h| / A_in and the return chamber is at tank pressure (0 gauge).
  Overrunning load (f_h v_x < 0, the load drives the rod): the meter-in chamber is only filled
  (p_L = 0) and the meter-out valve throttles the return chamber at |f_h| / A_out, so all the
  power the load returns, |f_h v_x|, is lost there: a valve recovers no energy.
* A cylinder with |v_x| below ``standstill_speed`` is held by its closed valve: no flow, and it
  does not set the load-sensing pressure.
* Pump pressure: (a) constant pressure, p_pump = p_s (a pressure-compensated variable pump
  delivering exactly the flow needed at the supply pressure p_s); (b) load sensing,
  p_pump = max_i p_L,i + Delta p_LS over the moving cylinders (Delta p_LS at standstill, with
  zero flow). Pump flow Q_pump = sum_i Q_i.
* Throttling: meter-in (p_pump - p_L,i) Q_i, meter-out |f_h v_x| for overrunning loads.
* Pump hydraulic power p_pump Q_pump >= 0; electric input P_in = p_pump Q_pump / (eta_pump eta_motor).

Energy balance (each term integrated by the trapezoid rule, as every energy of hiab-sim):

    E_in = sum_i (W_useful,i + E_friction,i + E_meter_in,i + E_meter_out,i) + E_pump_motor_loss

with W_useful = int f_x v_x dt (negative where the load returns energy), E_friction =
int (b v_x^2 + F_c |v_x|) dt. Where p_L > p_pump (constant pressure only: the cylinder would
stall) the meter-in loss is negative; such samples are counted in ``pressure_shortfall_samples``.

Published anchors (not used in the computation): valve-controlled crane system efficiency of
about 8.5 % conventional to 27 % load sensing (Liang et al. 1999); motor-controlled cylinders
using 60-64 % less energy than valve-controlled ones on a lab knuckle-boom crane (Frontiers in
Mechanical Engineering 2025, doi:10.3389/fmech.2025.1535120).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hiab_sim.arrays import Array
from hiab_sim.checks import check_efficiency
from hiab_sim.errors import InvalidInputError
from hiab_sim.hydraulics.cylinders import HydraulicSystem

#: The two supply variants, in the order :func:`hydraulic_baseline` returns them.
VARIANTS: tuple[str, ...] = ("constant_pressure", "load_sensing")


@dataclass(frozen=True)
class HydraulicSupplyParams:
    """Pump, drive motor and valve parameters of the hydraulic baseline.

    Attributes:
        load_sensing_margin: Delta p_LS [Pa] > 0, pump pressure above the highest load pressure
            (estimate: 1.5-3 MPa is the usual LS margin of mobile valves; 2.0 MPa).
        pump_efficiency: eta_pump in (0, 1], overall efficiency of the variable-displacement
            piston pump (estimate: 0.85, typical of axial piston pumps near their design point).
        motor_efficiency: eta_motor in (0, 1], the electric motor driving the pump, as on an
            electrified truck's e-PTO (estimate: 0.92, an IE3 motor of about 10 kW).
        standstill_speed: |v_x| [m/s] >= 0 below which a cylinder's valve is closed (model:
            1 mm/s, about 0.3 L/min for the 80 mm bore).
        supply_pressure: p_s [Pa] override, or None for the crane file's ``supply_pressure``.

    """

    load_sensing_margin: float = 2.0e6
    pump_efficiency: float = 0.85
    motor_efficiency: float = 0.92
    standstill_speed: float = 1.0e-3
    supply_pressure: float | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.load_sensing_margin) and self.load_sensing_margin > 0):
            raise InvalidInputError("hydraulics.load_sensing_margin", self.load_sensing_margin, "must be > 0", "Pa")
        check_efficiency("hydraulics.pump_efficiency", self.pump_efficiency)
        check_efficiency("hydraulics.motor_efficiency", self.motor_efficiency)
        if not (math.isfinite(self.standstill_speed) and self.standstill_speed >= 0):
            raise InvalidInputError("hydraulics.standstill_speed", self.standstill_speed, "must be >= 0", "m/s")
        p = self.supply_pressure
        if p is not None and not (math.isfinite(p) and p > 0):
            raise InvalidInputError("hydraulics.supply_pressure", p, "must be > 0", "Pa")


@dataclass(frozen=True)
class CylinderFlows:
    """Per-sample cylinder quantities, arrays of shape (K, n).

    Attributes:
        fluid_force: f_h = f_x + b v_x + F_c sign(v_x) [N].
        inlet_flow: Q, flow the pump delivers to the meter-in chamber [m^3/s] (>= 0).
        load_pressure: p_L, pressure the meter-in chamber needs [Pa] (>= 0).
        meter_out_loss: |f_h v_x| for overrunning loads, else 0 [W].
        friction_loss: b v_x^2 + F_c |v_x| [W].
        useful_power: f_x v_x [W] (0 at standstill, where the closed valve holds the rod).
        moving: True where |v_x| >= standstill_speed.

    """

    fluid_force: Array
    inlet_flow: Array
    load_pressure: Array
    meter_out_loss: Array
    friction_loss: Array
    useful_power: Array
    moving: NDArray[np.bool_]


@dataclass(frozen=True)
class SupplyResult:
    """One supply variant over the cycle. Powers (K,) [W], energies [J], per-actuator arrays (n,).

    Attributes:
        variant: ``constant_pressure`` or ``load_sensing``.
        pump_pressure: p_pump [Pa], shape (K,).
        pump_flow: Q_pump [m^3/s], shape (K,).
        input_power: Electric power into the pump motor [W], shape (K,).
        input_energy: int P_in dt [J], the baseline's energy.
        input_energy_per_actuator: int p_pump Q_i dt / (eta_pump eta_motor) [J], summing to input_energy.
        useful_work: int f_x v_x dt [J] per actuator (v_x = 0 below the standstill speed).
        delivered_work: int max(f_x v_x, 0) dt [J] per actuator, the work done on the load.
        friction_loss: [J] per actuator.
        meter_in_loss: int (p_pump - p_L) Q dt [J] per actuator.
        meter_out_loss: [J] per actuator.
        pump_motor_loss: int (P_in - p_pump Q_pump) dt [J].
        max_load_pressure: Largest p_L of any moving cylinder [Pa].
        pressure_shortfall_samples: Samples where some p_L exceeds p_pump (constant pressure only).

    """

    variant: str
    pump_pressure: Array
    pump_flow: Array
    input_power: Array
    input_energy: float
    input_energy_per_actuator: Array
    useful_work: Array
    delivered_work: Array
    friction_loss: Array
    meter_in_loss: Array
    meter_out_loss: Array
    pump_motor_loss: float
    max_load_pressure: float
    pressure_shortfall_samples: int

    @property
    def system_efficiency(self) -> float:
        """Work delivered to the loads over input energy [-] (Liang et al. 1999: about 0.085 to 0.27).

        The delivered work (f_x v_x > 0 only) is used because a closed cycle's net work is about 0:
        what the loads return while lowering is throttled, not recovered.
        """
        return float(np.sum(self.delivered_work) / self.input_energy) if self.input_energy > 0 else float("nan")


def cylinder_flows(
    force: ArrayLike, velocity: ArrayLike, cylinders: HydraulicSystem, params: HydraulicSupplyParams
) -> CylinderFlows:
    """Return the meter-in flows, load pressures and valve/friction losses of each cylinder.

    Args:
        force: Rod force f_x [N], shape (K, n) with columns in :attr:`HydraulicSystem.cylinders` order.
        velocity: Rod velocity v_x [m/s], shape (K, n).
        cylinders: Geometry, supply pressure and friction.
        params: Supply parameters (``standstill_speed``).

    """
    f, v = (np.asarray(x, dtype=float) for x in (force, velocity))
    cyl = tuple(cylinders)
    if f.ndim != 2 or f.shape[1] != len(cyl) or v.shape != f.shape:
        raise InvalidInputError("force, velocity", f"shapes {f.shape}, {v.shape}", f"must both be (K, {len(cyl)})")
    a_p = np.array([c.piston_area for c in cyl])
    a_r = np.array([c.annulus_area for c in cyl])
    moving = np.abs(v) >= params.standstill_speed
    v_eff = np.where(moving, v, 0.0)
    friction_force = cylinders.viscous_friction * v_eff + cylinders.coulomb_friction * np.sign(v_eff)
    f_h = f + friction_force
    extending = v_eff > 0
    a_in = np.where(extending, a_p, a_r)
    flow = a_in * np.abs(v_eff)
    p_fluid = f_h * v_eff
    resistive = p_fluid > 0
    return CylinderFlows(
        fluid_force=f_h,
        inlet_flow=flow,
        load_pressure=np.where(resistive, np.abs(f_h) / a_in, 0.0),
        meter_out_loss=np.where(p_fluid < 0, -p_fluid, 0.0),
        friction_loss=friction_force * v_eff,
        useful_power=f * v_eff,
        moving=moving,
    )


def hydraulic_baseline(
    time: ArrayLike,
    force: ArrayLike,
    velocity: ArrayLike,
    cylinders: HydraulicSystem,
    params: HydraulicSupplyParams | None = None,
) -> tuple[SupplyResult, SupplyResult]:
    """Return the (constant-pressure, load-sensing) baselines for rod forces and velocities on a time grid.

    Args:
        time: Strictly increasing sample times [s], shape (K,).
        force: Rod force f_x [N], shape (K, n).
        velocity: Rod velocity v_x [m/s], shape (K, n).
        cylinders: The crane's cylinders (:func:`~hiab_sim.hydraulics.cylinders.hydraulic_cylinders_from_mapping`).
        params: Supply parameters (defaults when None).

    """
    params = HydraulicSupplyParams() if params is None else params
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.diff(t) > 0):
        raise InvalidInputError("time", f"shape {t.shape}", "must be strictly increasing with at least 2 samples")
    flows = cylinder_flows(force, velocity, cylinders, params)
    if flows.inlet_flow.shape[0] != t.size:
        raise InvalidInputError("force", f"{flows.inlet_flow.shape[0]} samples", f"must match time's {t.size}")
    h = np.diff(t)
    w = np.zeros_like(t)
    w[:-1] += 0.5 * h
    w[1:] += 0.5 * h
    useful = w @ flows.useful_power
    friction = w @ flows.friction_loss
    meter_out = w @ flows.meter_out_loss
    moving_pressure = np.where(flows.moving, flows.load_pressure, 0.0)
    p_s = cylinders.supply_pressure if params.supply_pressure is None else params.supply_pressure
    pressures = {
        "constant_pressure": np.full(t.size, p_s),
        "load_sensing": moving_pressure.max(axis=1) + params.load_sensing_margin,
    }
    eta = params.pump_efficiency * params.motor_efficiency
    results = []
    for variant in VARIANTS:
        p_pump = pressures[variant]
        q_pump = flows.inlet_flow.sum(axis=1)
        p_hyd = p_pump * q_pump
        p_in = p_hyd / eta
        shortfall = np.any(flows.load_pressure > p_pump[:, None], axis=1)
        results.append(
            SupplyResult(
                variant=variant,
                pump_pressure=p_pump,
                pump_flow=q_pump,
                input_power=p_in,
                input_energy=float(w @ p_in),
                input_energy_per_actuator=w @ (p_pump[:, None] * flows.inlet_flow) / eta,
                useful_work=useful,
                delivered_work=w @ np.maximum(flows.useful_power, 0.0),
                friction_loss=friction,
                meter_in_loss=w @ ((p_pump[:, None] - flows.load_pressure) * flows.inlet_flow),
                meter_out_loss=meter_out,
                pump_motor_loss=float(w @ (p_in - p_hyd)),
                max_load_pressure=float(moving_pressure.max()),
                pressure_shortfall_samples=int(np.count_nonzero(shortfall)),
            )
        )
    return results[0], results[1]

"""Structural rows of a machine file's NLP: screw buckling, pin peak loads, the lowest natural frequency.

The rows of :mod:`hiab_sim.study.constraints.structure_rows` for a study of a machine file (``machine:``),
through the machine's description and Newton-Euler path instead of the crane's closed form:

* :class:`MachineBucklingRows` (``structure.buckling``): 1 - n f / P_cr(s) >= 0 per actuator with
  screw data, s the pin-to-pin column x0 + x (:mod:`hiab_sim.structure.machine_structure`). Exact
  partials: du = n (df P_cr - f dP_cr) / P_cr^2 with df the inverse dynamics' partials and
  dP_cr = (dP_cr/ds) ds, ds = dx (the loop closure's exact stroke partials,
  :meth:`~hiab_sim.study.machines.machine_model.MachineModel.stroke_margin_partials`) + dx0 (x0 =
  Lc0 + Lc, or the ``retracted_length`` variable itself where the chain declares one);
* :class:`MachinePinLoadRows` (``structure.pin_load_limits``): 1 - |F_p| / F_max >= 0 per limited pin
  (Newton-Euler pin forces), partials by central differences (all samples at once);
* :class:`MachineFrequencyRows` (``structure.min_natural_frequency_Hz``): f_1 / f_min - 1 >= 0 at each
  sample's pose with the payload held at the TCP (:mod:`hiab_sim.structure.machine_modes`), partials
  by central differences of the positions and the design.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.dynamics.paths import make_machine_dynamics
from hiab_sim.structure.buckling import critical_load
from hiab_sim.structure.machine_modes import machine_natural_frequencies
from hiab_sim.structure.machine_structure import machine_pin_loads
from hiab_sim.study.constraints.structure_rows import (
    BucklingRowsBase,
    FrequencyRowsBase,
    PinLoadRowsBase,
    StructureRowKinds,
)
from hiab_sim.study.machines.machine_model import MachineModel
from hiab_sim.study.nlp.interface import SamplePartials, SampleRows, SampleState


def _retracted_partials(model: MachineModel, chain: Any) -> Array:
    """dx0/dXi (n_xi,) of a chain's retracted length x0 = Lc0 + Lc (or its ``retracted_length`` variable)."""
    out = np.zeros(len(model.design_names))
    retracted = any(v.kind == "retracted_length" for v in chain.variables)
    counted = ("retracted_length",) if retracted else ("piston_offset", "rod_length")
    for v in chain.variables:
        if v.kind in counted:
            out[model.design_names.index(v.key)] = 1.0
    return out


class MachineBucklingRows(BucklingRowsBase):
    """1 - n f / P_cr per actuator with screw data and sample, on a machine file (module docstring)."""

    model: MachineModel

    def __init__(self, times: Array, model: MachineModel, emlas: EmlaSet, safety_factor: float) -> None:
        super().__init__(times, model, safety_factor)
        by_name = {p.name: p for p in emlas}
        names = model.actuator_names
        self.columns = tuple(k for k, name in enumerate(names) if by_name[name].screw is not None)
        for k in self.columns:
            chain, screw = model.machine.chains[k], by_name[names[k]].screw
            if chain.kind == "direct" and screw is not None and screw.retracted_length is None:
                raise InvalidInputError(
                    f"{names[k]}.screw.retracted_length", None, "a direct actuator's buckling row needs it", "m"
                )
        self.screws = tuple(by_name[names[k]].screw for k in self.columns)
        self.sample_rows = tuple(f"{names[k]} push <= P_cr / n" for k in self.columns)

    def _columns(self, state: SampleState) -> tuple[Array, Array, Array]:
        """S (K, r) [m], ds/dq (K, r, n) and ds/dXi (K, r, n_xi) of the buckled actuators."""
        model, q = self.model, state.joints.position
        machine = model.machine_at(state.lengths)
        margins = model.stroke_margins(state.lengths, q)
        dq_m, dxi_m = model.stroke_margin_partials(state.lengths, q)
        stroke_row = {name: 3 * c for c, name in enumerate(model.stroke_chains)}
        chains = {c.actuator.emla or c.name: c for c in machine.chains}  # by EMLA (actuator) name
        K, n, nxi = q.shape[0], q.shape[1], len(model.design_names)
        s = np.zeros((K, len(self.columns)))
        ds_dq = np.zeros((K, len(self.columns), n))
        ds_dxi = np.zeros((K, len(self.columns), nxi))
        for r, (k, screw) in enumerate(zip(self.columns, self.screws, strict=True)):
            assert screw is not None
            name = model.actuator_names[k]
            chain = chains[name]
            if chain.kind == "direct":
                j = model.joint_names.index(chain.joint)
                if screw.retracted_length is None:
                    raise AssertionError(f"{name}: a direct actuator's screw has its retracted_length (loader)")
                s[:, r] = screw.retracted_length + q[:, j]
                ds_dq[:, r, j] = 1.0
                continue
            row = stroke_row[chain.name]
            x0 = float(chain.actuator.piston_offset or 0.0) + float(chain.actuator.rod_length or 0.0)
            s[:, r] = x0 + margins[:, row]
            ds_dq[:, r] = dq_m[:, row]
            ds_dxi[:, r] = dxi_m[:, row] + _retracted_partials(model, chain)
        return s, ds_dq, ds_dxi

    def _loads(self, s: Array) -> tuple[Array, Array]:
        out = [critical_load(screw, s[:, r]) for r, screw in enumerate(self.screws)]  # type: ignore[arg-type]
        return np.stack([o[0] for o in out], axis=1), np.stack([o[1] for o in out], axis=1)

    def values(self, state: SampleState) -> Array:
        """1 - u per sample, sample-major (K * r,)."""
        s, _, _ = self._columns(state)
        load, _ = self._loads(s)
        f = np.asarray(state.actuators.force, dtype=float)[:, list(self.columns)]
        return (1.0 - self.safety_factor * f / load).ravel()

    def jacobian(self, state: SampleState, partials: SamplePartials) -> SampleRows:
        """-du/dq (positions, rates, accelerations) and -du/dXi (exact; module docstring)."""
        s, ds_dq, ds_dxi = self._columns(state)
        load, slope = self._loads(s)
        cols = list(self.columns)
        f = np.asarray(state.actuators.force, dtype=float)[:, cols]
        df_dq = partials.id_q[:, cols, :]
        df_dxi = partials.id_xi[:, cols, :]
        n = ds_dq.shape[2]
        dP_dq = np.zeros_like(df_dq)
        dP_dq[:, :, :n] = slope[:, :, None] * ds_dq
        dP_dxi = slope[:, :, None] * ds_dxi
        factor = (self.safety_factor / load)[:, :, None]
        ratio = (f / load)[:, :, None]
        return SampleRows(-factor * (df_dq - ratio * dP_dq), -factor * (df_dxi - ratio * dP_dxi))


class MachinePinLoadRows(PinLoadRowsBase):
    """1 - |F_p| / F_max per limited pin and sample (Newton-Euler pin forces of the machine)."""

    model: MachineModel

    def _magnitudes(self, design: Any, position: Array, velocity: Array, acceleration: Array) -> Array:
        machine = self.model.machine_at(design)
        force = None if self.tcp_force is None else self.tcp_force[:, :2]
        out = make_machine_dynamics(machine, None, "newton_euler")(position, velocity, acceleration, tcp_force=force)
        loads = machine_pin_loads(machine, position, out.pins)
        names = [pin.name for pin in loads.pins]
        index = [names.index(name) for name, _ in self.limits]
        return loads.magnitude[:, index]


class MachineFrequencyRows(FrequencyRowsBase):
    """f_1(q_k, design) / f_min - 1 per sample: the lowest locked-rotor frequency at the sample's pose."""

    model: MachineModel

    def _lowest_Hz(self, design: Any, position: Array) -> Array:
        machine = self.model.machine_at(design)
        inverse = make_machine_dynamics(machine, None, "newton_euler")
        force = None if self.tcp_force is None else self.tcp_force[:, :2]
        modes = machine_natural_frequencies(
            machine, inverse, self.emlas, position, force, self.payload_kg, tracked=self.model.extra
        )
        return modes.lowest_Hz


#: A machine file's structural blocks (its description, the Newton-Euler path); :func:`structure_blocks` builds them.
MACHINE_ROWS = StructureRowKinds(
    MachineBucklingRows,
    lambda model, emlas: any(p.screw is not None for p in emlas),
    MachinePinLoadRows,
    MachineFrequencyRows,
)

"""One machine-file design's structural state along its motion: pins, screw buckling, natural frequencies.

The same summary as :mod:`hiab_sim.structure.summary` (the ``structure`` section of ``result.json``)
for a design of any machine file, from its inverse dynamics
(:func:`hiab_sim.machine.dynamics.paths.make_machine_dynamics`):

* pins: every hinge of the link tree and every loop pin (:class:`hiab_sim.machine.dynamics.tree.PinForces`;
  a prismatic joint carries a moment too and is no pin). The force reported is that of the member
  (``by``, the parent for a hinge) on the bracket (``on``), in the bracket's frame, as the crane's;
* buckling: a chain's screw is a column of its pin-to-pin length s = x0 + x (x0 = Lc0 + Lc, the
  retracted length of a triangle's or linkage's actuator, seed eq. ``qus_a``; a direct actuator's
  ``screw.retracted_length`` + x), P_cr of :func:`hiab_sim.structure.buckling.critical_load` and the
  utilisation u = n f / P_cr (f > 0 pushes); a direct actuator whose screw gives no retracted length
  has no column and is left out of the summary (the NLP's buckling rows refuse it by name);
* the lowest locked-rotor natural frequency along the motion and over a grid of the working range
  (:mod:`hiab_sim.structure.machine_modes`), when every actuator has screw and drive-stiffness data.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from hiab_sim.arrays import Array
from hiab_sim.dynamics.samples import JointSamples
from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.paths import MachineInverseDynamics
from hiab_sim.machine.dynamics.planar import close_loops, frames, planar_bodies
from hiab_sim.machine.dynamics.tree import PinForces, machine_tree, pin_layout
from hiab_sim.structure.buckling import DEFAULT_SAFETY_FACTOR, BucklingSamples, check_safety_factor, critical_load
from hiab_sim.structure.machine_modes import machine_natural_frequencies, machine_working_range_poses
from hiab_sim.structure.pin_loads import Pin, PinLoads
from hiab_sim.structure.summary import DesignStructure, has_stiffness, largest, summarise

#: Values per joint of the working-range grid for the frequencies (7^3 = 343 poses on a 3-joint machine).
WORKING_GRID_PER_JOINT = 7


def machine_pin_names(machine: Machine) -> tuple[str, ...]:
    """The machine's pins: every hinge of its link tree (named after its joint) and every loop pin."""
    names, kinds, _, _ = pin_layout(machine_tree(machine))
    return tuple(name for name, kind in zip(names, kinds, strict=True) if kind != "slide")


def machine_pin_loads(machine: Machine, position: ArrayLike, pins: PinForces) -> PinLoads:
    """The hinges and loop pins of a machine's pin forces as :class:`PinLoads`, member on bracket.

    The bracket of a pin is the body ``by`` (a hinge's parent, a loop pin's second body), the member
    ``on``: the force reported is the member's on the bracket, -F of :class:`PinForces`, in the
    bracket's frame R_b = Rz(theta_b) F_b (:mod:`hiab_sim.machine.dynamics.planar`; theta_b from the
    closed loops at the joint samples ``position`` (T, n)), as the crane's pins are.
    """
    tree = machine_tree(machine)
    planar = planar_bodies(tree)
    q = np.atleast_2d(np.asarray(position, dtype=float))
    theta = np.stack(frames(tree, planar, close_loops(tree, planar, q)).theta, axis=1)  # (T, n_bodies)
    index = {body.name: b for b, body in enumerate(tree.bodies)}
    chain_of = {chain.joint: chain.name for chain in machine.chains}
    keep = [p for p, kind in enumerate(pins.kinds) if kind != "slide"]
    out = []
    world = -np.asarray(pins.world, dtype=float)[:, keep]
    local = np.zeros_like(world)
    for column, p in enumerate(keep):
        name = pins.names[p]
        chain = chain_of.get(name, name.split(".")[0] if pins.kinds[p] == "loop" else "")
        out.append(Pin(name, chain, pins.kinds[p], pins.by[p], pins.on[p]))
        b = index[pins.by[p]]
        c, s = np.cos(theta[:, b]), np.sin(theta[:, b])
        turned = np.stack(
            [
                c * world[:, column, 0] + s * world[:, column, 1],
                -s * world[:, column, 0] + c * world[:, column, 1],
                np.zeros_like(c),
            ],
            axis=1,
        )
        local[:, column] = (turned @ planar[b].fixed)[:, :2]  # F_b^T Rz(-theta) F, row-vector form
    return PinLoads(tuple(out), world, local)


def emla_names(machine: Machine, chains: Sequence[str]) -> tuple[str, ...]:
    """The EMLA (actuator) name of each named chain: its ``actuator.emla``, else the chain's name."""
    of = {c.name: c.actuator.emla or c.name for c in machine.chains}
    return tuple(of[name] for name in chains)


def column_lengths(machine: Machine, emlas: EmlaSet, chains: Sequence[str], stroke: Array) -> Array:
    """Pin-to-pin column length s (T, n_a) [m] of each chain's actuator with screw data at the strokes (T, n_a).

    NaN where an actuator has no column: no ``screw`` section, or a direct actuator whose screw
    gives no ``retracted_length`` (its column's zero-stroke length is then unknown).
    """
    by_chain = {chain.name: chain for chain in machine.chains}
    by_name = {p.name: p for p in emlas}
    out = np.full(stroke.shape, np.nan)
    for k, (name, emla) in enumerate(zip(chains, emla_names(machine, chains), strict=True)):
        screw = by_name[emla].screw
        if screw is None:
            continue
        chain = by_chain[name]
        if chain.kind == "direct":
            if screw.retracted_length is None:
                continue
            x0 = screw.retracted_length
        else:
            x0 = float(chain.actuator.piston_offset or 0.0) + float(chain.actuator.rod_length or 0.0)
        out[:, k] = x0 + stroke[:, k]
    return out


def machine_buckling(
    machine: Machine,
    emlas: EmlaSet,
    names: Sequence[str],
    stroke: Array,
    force: Array,
    safety_factor: float = DEFAULT_SAFETY_FACTOR,
) -> BucklingSamples:
    """Buckling utilisation of every actuator with screw data, at strokes and forces (T, n_a) [m, N].

    ``names``: the chains in sample order; the samples are named by their EMLAs.
    """
    check_safety_factor(safety_factor)
    by_name = {p.name: p for p in emlas}
    length = column_lengths(machine, emlas, names, stroke)
    actuators = emla_names(machine, names)
    cols = [k for k in range(len(actuators)) if np.all(np.isfinite(length[:, k]))]  # the actuators with a column
    loads = []
    for k in cols:
        screw = by_name[actuators[k]].screw
        assert screw is not None
        loads.append(critical_load(screw, length[:, k])[0])
    T = stroke.shape[0]
    load = np.stack(loads, axis=1) if loads else np.zeros((T, 0))
    push = force[:, cols]
    return BucklingSamples(
        tuple(actuators[k] for k in cols), safety_factor, length[:, cols], load, push, safety_factor * push / load
    )


def machine_design_structure(
    machine: Machine,
    inverse: MachineInverseDynamics,
    emlas: EmlaSet,
    joints: JointSamples,
    tcp_force: ArrayLike | None = None,
    safety_factor: float = DEFAULT_SAFETY_FACTOR,
    payload_kg: float = 0.0,
    tracked: Sequence[str] | None = None,
) -> DesignStructure:
    """Structural summary of one machine design along its motion (module docstring).

    Args:
        machine: The machine at the design ``inverse`` was built for.
        inverse: Its inverse dynamics with pin forces (bare mechanism: load-side forces).
        emlas: EMLA set named by the machine's chains.
        joints: The motion's joint samples (T, n).
        tcp_force: Force of the environment on the TCP [N], world (x, y[, z]) (only x, y act), (3,) or (T, 3).
        safety_factor: Buckling safety factor n [-].
        payload_kg: Mass held at the TCP for the frequencies [kg] (its weight is in ``tcp_force``).
        tracked: The study's tracked coordinates beyond the TCP's x, y (the payload's kinematics).

    """
    force = None if tcp_force is None else np.asarray(tcp_force, dtype=float)[..., :2]
    out = inverse(joints.position, joints.velocity, joints.acceleration, tcp_force=force)
    loads = machine_pin_loads(machine, joints.position, out.pins)
    names = tuple(out.names)
    buckling = machine_buckling(machine, emlas, names, np.asarray(out.stroke), np.asarray(out.force), safety_factor)
    on_path = grid = None
    if has_stiffness(emlas):
        on_path = machine_natural_frequencies(
            machine, inverse, emlas, joints.position, force, payload_kg, tracked=tracked
        ).lowest_Hz
        poses = machine_working_range_poses(machine, WORKING_GRID_PER_JOINT)
        grid = machine_natural_frequencies(
            machine, inverse, emlas, poses, largest(force), payload_kg, tracked=tracked
        ).lowest_Hz
    return summarise(loads, buckling, safety_factor, on_path, grid)

"""Physics checks of the generic inverse dynamics: power balance, finite differences, free bodies, forward dynamics.

Each test compares a path with something it does not compute itself: the time derivative of the
machine's energy, finite differences of its own strokes, the weight of every body, a free-body
calculation by hand, and MuJoCo's constrained forward dynamics.
"""

from __future__ import annotations

import functools

import mujoco
import numpy as np
import pytest
from test_machine_dynamics_machines import (
    HAND_A,
    HAND_C,
    HAND_M,
    HAND_MC,
    HAND_MR,
    excavator,
    hand_machine,
    random_states,
)

from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.mjcf_build import build_machine_model
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.dynamics.newton_euler import NewtonEulerInverseDynamics
from hiab_sim.machine.dynamics.tree import PinForces, machine_tree
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine.parts import Pose, rot_z

XS031 = load_machine("xs031")
EXACT = load_machine("exact")
EXCAVATOR = excavator()
#: The test excavator standing on a 12 deg slope, its chassis frame moved off the world origin.
SLOPE = Pose((0.4, -0.2, 0.05), rot_z(np.radians(12.0)))
MACHINE_LIST = {
    "xs031": XS031,
    "exact": EXACT,
    "test-excavator": EXCAVATOR,
    "cylinder-on-driven-link": hand_machine(reversed_actuator=True),
    "on-a-slope": excavator(SLOPE),
}
MACHINES = pytest.mark.parametrize("machine", list(MACHINE_LIST.values()), ids=list(MACHINE_LIST))
PATHS = pytest.mark.parametrize("path", [NewtonEulerInverseDynamics, MujocoMachineDynamics], ids=["ne", "mujoco"])


def _along(q: np.ndarray, dq: np.ndarray, ddq: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """Position and rate at time t of q(t) = q + dq t + ddq t^2 / 2 (which has the sample's dq, ddq at t = 0)."""
    return q + dq * t + 0.5 * ddq * t**2, dq + ddq * t


@MACHINES
@PATHS
def test_power_balance_on_random_states(machine: Machine, path: type) -> None:
    """Sum f_x v_x + F . v_tcp = d/dt (kinetic + potential) (seed eq. dynamics), dE/dt by a 5-point stencil.

    The energies come from the path's own state but not from its forces: MuJoCo's
    ``mj_energyPos``/``mj_energyVel``, or sum m v^2 / 2 + I w^2 / 2 + m g y of the Newton-Euler bodies.
    """
    q, dq, ddq = random_states(machine, 30, seed=11)
    force = np.random.default_rng(12).normal(0.0, 1500.0, (30, 2))
    dynamics = path(machine)
    out = dynamics(q, dq, ddq, force)
    tcp = NewtonEulerInverseDynamics(machine).tcp_velocity(q, dq)
    power = out.power.sum(axis=1) + np.einsum("ti,ti->t", force, tcp)
    h = 1e-3
    energy = [sum(dynamics.energy(*_along(q, dq, ddq, k * h))) for k in (-2, -1, 1, 2)]
    rate = (energy[0] - 8.0 * energy[1] + 8.0 * energy[2] - energy[3]) / (12.0 * h)
    peak = float(np.max(np.abs(out.power)))
    assert peak > 100.0
    assert float(np.max(np.abs(power - rate))) < 1e-9 * peak  # measured 2e-12 (XS 031), 9e-13 (excavator)


@MACHINES
def test_actuator_rates_are_the_time_derivatives_of_the_strokes(machine: Machine) -> None:
    """v_x and a_x equal central differences of the strokes x(t) and v_x(t) along q(t) (error O(h^2))."""
    q, dq, ddq = random_states(machine, 20, seed=13)
    dynamics = NewtonEulerInverseDynamics(machine)
    out = dynamics(q, dq, ddq)
    h = 1e-5
    after, before = (dynamics(*_along(q, dq, ddq, s), ddq) for s in (h, -h))
    np.testing.assert_allclose((after.stroke - before.stroke) / (2 * h), out.velocity, atol=1e-8)
    np.testing.assert_allclose((after.velocity - before.velocity) / (2 * h), out.acceleration, atol=1e-6)


TCP_FORCE_AT_REST = np.array([300.0, -900.0])  # N, any load


@functools.cache
def _rest_pins(machine_id: str, path: type) -> PinForces:
    """Pin forces of five random static poses of a machine of :data:`MACHINE_LIST`, with a TCP load."""
    machine = MACHINE_LIST[machine_id]
    q, _, _ = random_states(machine, 5, seed=14)
    return path(machine)(q, np.zeros_like(q), np.zeros_like(q), TCP_FORCE_AT_REST).pins


@PATHS
@pytest.mark.parametrize(
    ("machine_id", "body"),
    [(key, body.name) for key, machine in MACHINE_LIST.items() for body in machine_tree(machine).bodies[1:]],
)
def test_forces_at_rest_balance_the_weight_of_each_body(machine_id: str, body: str, path: type) -> None:
    """At rest, the body's joint and pin forces plus its weight (and the TCP force on its link) sum to zero."""
    machine = MACHINE_LIST[machine_id]
    tree = machine_tree(machine)
    b = tree.index(body)
    pins = _rest_pins(machine_id, path)
    total = np.zeros((pins.world.shape[0], 2))
    for k, (on, by) in enumerate(zip(pins.on, pins.by, strict=True)):
        total += pins.world[:, k] * ((on == body) - (by == body))
    inertia = tree.bodies[b].inertia
    total[:, 1] -= (0.0 if inertia is None else inertia.mass) * machine.gravity
    if b == tree.tcp_body:
        total += TCP_FORCE_AT_REST
    touching = [on == body or by == body for on, by in zip(pins.on, pins.by, strict=True)]
    assert np.any(np.abs(pins.world[:, touching]) > 1.0)  # the body is held by loaded joints
    assert np.max(np.abs(total)) < 1e-10 * max(float(np.max(np.abs(pins.world))), 1.0)


@PATHS
@pytest.mark.parametrize("reversed_actuator", [False, True], ids=["cylinder-below", "cylinder-on-boom"])
def test_pin_forces_of_a_static_boom_match_a_free_body_calculation(path: type, reversed_actuator: bool) -> None:
    """Horizontal boom of mass M (com at x = C), vertical actuator at x = A, load W at x = 2 m, at rest.

    By hand: the actuator is a two-force member but for its own weight along its axis, so the
    boom's moment about its hinge gives the upward force N = (M g C + 2 W) / A the actuator's top pin
    applies to the boom; the hinge carries M g + W - N, the bottom (ground) pin N + (Mc + Mr) g. The
    actuator force is N plus the weight of its upper part: f = N + Mr g with the rod on top, N + Mc g
    with the cylinder on top.
    """
    g, W = 9.81, 500.0
    machine = hand_machine(reversed_actuator)
    out = path(machine)(np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), np.array([0.0, -W]))
    N = (HAND_M * g * HAND_C + 2.0 * W) / HAND_A
    np.testing.assert_allclose(out.force[0, 0], N + (HAND_MC if reversed_actuator else HAND_MR) * g, rtol=1e-12)
    np.testing.assert_allclose(out.stroke[0, 0], 0.1, atol=1e-12)
    pins = out.pins
    np.testing.assert_allclose(pins.force("hinge")[0], [0.0, HAND_M * g + W - N], atol=1e-9)
    top, bottom = ("act.base_pin", "act.end_pin") if reversed_actuator else ("act.end_pin", "act.base_pin")
    # base_pin: on the cylinder by its link; end_pin: on the rod by its link
    np.testing.assert_allclose(pins.force(top)[0], [0.0, -N], atol=1e-9)
    np.testing.assert_allclose(pins.force(bottom)[0], [0.0, N + (HAND_MC + HAND_MR) * g], atol=1e-9)
    # in the actuator's frame (x from its base pivot to its end pivot) the top pin pushes towards the base
    sign = 1.0 if reversed_actuator else -1.0
    np.testing.assert_allclose(pins.local[0, pins.names.index(top)], [sign * N, 0.0, 0.0], atol=1e-9)


def test_constrained_forward_dynamics_reproduces_the_accelerations() -> None:
    """Constrained MuJoCo forward dynamics driven by the Newton-Euler forces accelerates the joints as sampled.

    The loops are soft ``connect`` equalities there; their compliance (solref/solimp) is the remaining
    difference, bounded at 1 % of the largest acceleration.
    """
    q, dq, ddq = random_states(EXACT, 6, seed=15)
    forces = NewtonEulerInverseDynamics(EXACT)(q, dq, ddq).force
    mj = MujocoMachineDynamics(EXACT)
    qpos, qvel, _ = mj.state(q, dq, ddq)
    model = build_machine_model(EXACT)
    data = mujoco.MjData(model)
    joints = [int(model.joint(name).dofadr[0]) for name in EXACT.joint_names]
    for i in range(len(q)):
        data.qpos[:], data.qvel[:], data.ctrl[:] = qpos[i], qvel[i], forces[i]
        mujoco.mj_forward(model, data)
        assert np.max(np.abs(data.qacc[joints] - ddq[i])) < 1e-2 * max(np.max(np.abs(ddq[i])), 1.0)

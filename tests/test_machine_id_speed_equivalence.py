"""The vectorised Newton-Euler path equals a straightforward evaluation, design by design and in batches.

The reference here is the path as first written: loop closure by the loop Jacobian
(:func:`hiab_sim.machine.dynamics.planar.loop_state`), body frames one by one
(:func:`~hiab_sim.machine.dynamics.planar.frames`), every body's Newton-Euler force summed tip to
base with every loop-pin force as an unknown, and one dense solve of all hinge equations per
sample; the designed machine's tree built by :meth:`Machine.with_design`. The fast path shares
none of it: closed-form closure, in-place arrays, block solve, design numbers without a tree.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from test_machine_dynamics import EXACT, EXCAVATOR, MACHINES, SLOPE, XS031, payload_forces, relative
from test_machine_dynamics_machines import excavator, random_states

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.ne_design import design_constants
from hiab_sim.machine.dynamics.ne_layout import layout_of
from hiab_sim.machine.dynamics.newton_euler import NewtonEulerInverseDynamics, batched_inverse_dynamics
from hiab_sim.machine.dynamics.planar import frames, loop_state, planar_bodies
from hiab_sim.machine.dynamics.tree import PinForces, SimulationExtras, machine_tree, pin_layout


def _cross(a: np.ndarray | complex, b: np.ndarray | complex) -> np.ndarray:
    return np.asarray((np.conj(a) * b).imag)


def reference(machine: Machine, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray, tcp: np.ndarray) -> dict:
    """Full state, actuator forces and pin forces by the straightforward evaluation (see the module docstring)."""
    tree = machine_tree(machine)
    planar = planar_bodies(tree)
    qf, dqf, ddqf = loop_state(tree, planar, q, dq, ddq)
    fk = frames(tree, planar, qf, dqf, ddqf)
    T, n, pins = len(q), len(tree.bodies), 2 * len(tree.loops)
    force = [np.zeros(T, complex) for _ in range(n)]
    moment = [np.zeros(T) for _ in range(n)]
    force_per = [np.zeros((T, pins), complex) for _ in range(n)]
    moment_per = [np.zeros((T, pins)) for _ in range(n)]
    for b in range(1, n):
        com, _, acc = fk.point(b, planar[b].com)
        net = planar[b].mass * (acc + 1j * tree.gravity)
        force[b] += net
        moment[b] += planar[b].inertia_zz * fk.alpha[b] + _cross(com, net)
    external = tcp[:, 0] + 1j * tcp[:, 1]
    at = fk.point(tree.tcp_body, planar[tree.tcp_body].point(np.asarray(tree.tcp.position)))[0]
    force[tree.tcp_body] -= external
    moment[tree.tcp_body] -= _cross(at, external)
    for k, loop in enumerate(tree.loops):
        on_a = fk.point(loop.body_a, planar[loop.body_a].point(loop.point_a))[0]
        on_b = fk.point(loop.body_b, planar[loop.body_b].point(loop.point_b))[0]
        for j, unit in enumerate((1.0 + 0j, 1j)):
            force_per[loop.body_a][:, 2 * k + j] -= unit
            moment_per[loop.body_a][:, 2 * k + j] -= _cross(on_a, unit)
            force_per[loop.body_b][:, 2 * k + j] += unit
            moment_per[loop.body_b][:, 2 * k + j] += _cross(on_b, unit)
    for b in range(n - 1, 0, -1):
        p = tree.bodies[b].parent
        if p > 0:
            force[p] += force[b]
            moment[p] += moment[b]
            force_per[p] += force_per[b]
            moment_per[p] += moment_per[b]
    hinges = [b for b, body in enumerate(tree.bodies) if body.kind == "revolute"]
    lam = np.zeros((T, pins))
    for t in range(T):  # one dense solve per sample
        rows = np.array([moment_per[b][t] - _cross(fk.z[b][t], force_per[b][t]) for b in hinges])
        rhs = np.array([_cross(fk.z[b][t], force[b][t]) - moment[b][t] for b in hinges])
        lam[t] = np.linalg.solve(rows, rhs)
    moved = [force[b] + np.einsum("tl,tl->t", force_per[b], lam) for b in range(n)]
    act = list(tree.actuated)
    axis = [fk.rot[tree.bodies[b].parent] * planar[b].axis for b in act]
    world = [np.stack([moved[b].real, moved[b].imag], axis=1) for b in range(1, n)]
    world += [lam[:, 2 * k : 2 * k + 2] for k in range(len(tree.loops))]
    on = [*range(1, n), *(loop.body_a for loop in tree.loops)]
    local = []
    for f, b in zip(world, on, strict=True):
        c, s = np.cos(fk.theta[b]), np.sin(fk.theta[b])
        local.append(np.stack([c * f[:, 0] + s * f[:, 1], -s * f[:, 0] + c * f[:, 1], 0 * c], 1) @ planar[b].fixed)
    return {
        "state": (qf, dqf, ddqf),
        "force": np.stack([(np.conj(u) * moved[b]).real for u, b in zip(axis, act, strict=True)], axis=1),
        "velocity": dqf[:, act],
        "acceleration": ddqf[:, act],
        "stroke": qf[:, act],
        "world": np.stack(world, axis=1),
        "local": np.stack(local, axis=1),
    }


def in_bounds(machine: Machine, rng: np.random.Generator) -> np.ndarray:
    """A random design inside the declared bounds (middle 60 % of each)."""
    return np.array([v.low + (v.high - v.low) * rng.uniform(0.2, 0.8) for v in machine.decision_variables])


@MACHINES
@pytest.mark.parametrize("designed", [False, True], ids=["file", "random-design"])
def test_fast_path_equals_the_straightforward_evaluation(machine: Machine, designed: bool) -> None:
    """Actuator forces, rates, strokes, joint and pin forces and the full state agree to 1e-12 (measured ~1e-15)."""
    rng = np.random.default_rng(21)
    design = in_bounds(machine, rng) if designed and machine.decision_variables else None
    q, dq, ddq = random_states(machine, 40, seed=22)
    tcp = payload_forces(40, seed=23)
    out = NewtonEulerInverseDynamics(machine, design)(q, dq, ddq, tcp)
    ref = reference(machine if design is None else machine.with_design(design), q, dq, ddq, tcp)
    for key in ("force", "velocity", "acceleration"):
        assert relative(getattr(out, key), ref[key]) < 1e-12, key
    np.testing.assert_allclose(out.stroke, ref["stroke"], rtol=0, atol=1e-13)
    assert relative(out.pins.world, ref["world"]) < 1e-12
    assert np.max(np.abs(out.pins.local - ref["local"])) < 1e-12 * np.max(np.abs(ref["world"]))
    state = NewtonEulerInverseDynamics(machine, design).state(q, dq, ddq)
    np.testing.assert_allclose(np.angle(np.exp(1j * (state[0] - ref["state"][0]))), 0.0, atol=1e-12)
    for got, want in zip(state[1:], ref["state"][1:], strict=True):
        assert relative(got, want) < 1e-12


@pytest.mark.parametrize("machine", [XS031, EXACT, excavator(SLOPE)], ids=["xs031", "exact", "on-a-slope"])
def test_design_numbers_equal_those_of_the_designed_tree(machine: Machine) -> None:
    """Origins, bodies, loop points and x0 of five designs at once equal with_design's tree (1e-14)."""
    rng = np.random.default_rng(31)
    designs = np.array([in_bounds(machine, rng) for _ in range(5)])
    numbers = design_constants(machine, layout_of(machine), designs)
    for d, values in enumerate(designs):
        tree = machine_tree(machine.with_design(values))
        planar = planar_bodies(tree)
        expected = {
            "origin": [p.origin for p in planar],
            "mass": [p.mass for p in planar],
            "com": [p.com for p in planar],
            "izz": [p.inertia_zz for p in planar],
            "point_a": [planar[k.body_a].point(k.point_a) for k in tree.loops],
            "point_b": [planar[k.body_b].point(k.point_b) for k in tree.loops],
        }
        for key, want in expected.items():
            got = getattr(numbers, key)[:, d]
            np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-14, err_msg=key)
        x0 = [0.0 if c.kind == "direct" else c.actuator.retracted_length for c in tree.machine.chains]
        np.testing.assert_allclose(numbers.x0[:, d], x0, rtol=1e-14)


@pytest.mark.parametrize("machine", [XS031, EXACT], ids=["xs031", "exact"])
@pytest.mark.parametrize("per_design", [False, True], ids=["shared-samples", "samples-per-design"])
def test_batched_designs_equal_separate_calls(machine: Machine, per_design: bool) -> None:
    """D designs in one call give each design's own forces, rates and strokes (1e-12), with extras and a TCP force."""
    rng = np.random.default_rng(41)
    designs = np.array([in_bounds(machine, rng) for _ in range(4)])
    n = len(machine.chains)
    extras = SimulationExtras(tuple(rng.uniform(0.0, 50.0, n)), tuple(rng.uniform(0.0, 900.0, n)))
    samples = [random_states(machine, 30, seed=42 + d) for d in range(4 if per_design else 1)]
    tcp = payload_forces(30, seed=47)
    joints = [np.stack([s[k] for s in samples]) if per_design else samples[0][k] for k in range(3)]
    got = batched_inverse_dynamics(machine, designs, *joints, tcp_force=tcp, extras=extras)
    for d, values in enumerate(designs):
        q, dq, ddq = samples[d if per_design else 0]
        one = NewtonEulerInverseDynamics(machine, values, extras)(q, dq, ddq, tcp)
        for series, want in zip(got, (one.force, one.velocity, one.acceleration, one.stroke), strict=True):
            assert series.shape == (4, 30, n)
            assert relative(series[d], want) < 1e-12


def test_results_survive_the_next_call_and_pins_are_those_of_their_own_samples() -> None:
    """Arrays kept between calls are never handed out: a second call changes neither the first's forces nor its pins."""
    dynamics = NewtonEulerInverseDynamics(EXCAVATOR)
    q, dq, ddq = random_states(EXCAVATOR, 25, seed=51)
    first = dynamics(q, dq, ddq, [100.0, -400.0])
    kept = first.force.copy()
    q2, dq2, ddq2 = random_states(EXCAVATOR, 25, seed=52)
    dynamics(q2, dq2, ddq2)
    q[:], dq[:], ddq[:] = q2, dq2, ddq2  # the caller reuses its arrays before reading the pins
    np.testing.assert_array_equal(first.force, kept)
    q1, dq1, ddq1 = random_states(EXCAVATOR, 25, seed=51)
    ref = reference(EXCAVATOR, q1, dq1, ddq1, np.tile([100.0, -400.0], (25, 1)))
    assert relative(first.pins.world, ref["world"]) < 1e-12
    copy = pickle.loads(pickle.dumps(first.pins))
    assert type(copy) is PinForces
    np.testing.assert_array_equal(copy.world, first.pins.world)
    np.testing.assert_array_equal(copy.local, first.pins.local)
    assert copy.names == pin_layout(machine_tree(EXCAVATOR))[0]


def test_designed_machine_is_the_checked_with_design() -> None:
    """The object's machine is Machine.with_design's; a design outside the bounds is refused at construction."""
    values = in_bounds(XS031, np.random.default_rng(61))
    designed = NewtonEulerInverseDynamics(XS031, values).machine
    np.testing.assert_allclose(designed.design_values(), values, rtol=0, atol=1e-15)
    high = values.copy()
    high[0] = XS031.decision_variables[0].high + 0.01
    with pytest.raises(InvalidInputError, match=XS031.variable_keys[0]):
        NewtonEulerInverseDynamics(XS031, high)
    with pytest.raises(InvalidInputError, match="design"):
        NewtonEulerInverseDynamics(XS031, values[:3])


def test_batch_names_its_bad_inputs() -> None:
    """Malformed designs and joint samples raise InvalidInputError naming the field."""
    q, dq, ddq = random_states(XS031, 5, seed=71)
    designs = np.repeat(XS031.design_values()[None], 2, axis=0)
    with pytest.raises(InvalidInputError, match="designs"):
        batched_inverse_dynamics(XS031, designs[:, :4], q, dq, ddq)
    bad = designs.copy()
    bad[1, 1] = np.nan
    with pytest.raises(InvalidInputError, match="designs"):
        batched_inverse_dynamics(XS031, bad, q, dq, ddq)
    with pytest.raises(InvalidInputError, match="position"):
        batched_inverse_dynamics(XS031, designs, np.stack([q, q, q]), np.stack([dq] * 3), np.stack([ddq] * 3))
    with pytest.raises(InvalidInputError, match="tcp_force"):
        batched_inverse_dynamics(XS031, designs, q, dq, ddq, tcp_force=np.zeros(3))

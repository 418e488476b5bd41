"""The XS 031 machine file describes the same crane as the crane file: closure, kinematics, bodies, design."""

from __future__ import annotations

import numpy as np
import pytest

from hiab_sim.crane import kinematics as crane_kinematics
from hiab_sim.crane import mechanism
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.to_machine import machine_from_crane
from hiab_sim.machine.description import Machine
from hiab_sim.machine.kinematics import closure
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine.loader import load_machine


@pytest.fixture(scope="module")
def machine() -> Machine:
    """The shipped XS 031 machine file."""
    return load_machine("xs031")


def _random_joints(machine: Machine, rng: np.random.Generator, n: int) -> np.ndarray:
    ranges = [machine.joint_link(j).joint_range for j in machine.joint_names]
    return np.stack([rng.uniform(low, high, n) for low, high in ranges], axis=-1)  # type: ignore[misc]


def _random_lengths(rng: np.random.Generator, n: int) -> list[np.ndarray]:
    """Link-length sets near the default that still serve the working ranges."""
    base = np.array([1.0071227324212, 0.085, 0.745, 1.132185817991, 0.085, 0.745])
    return [base + rng.uniform(-0.01, 0.01, 6) for _ in range(n)]


def test_decision_variables_are_the_seeds_six(machine: Machine) -> None:
    """The XS 031 keeps exactly today's six variables: [L, Lc0, Lc] of lift then tilt, at the crane's values."""
    assert machine.variable_keys == ["lift.L", "lift.Lc0", "lift.Lc", "tilt.L", "tilt.Lc0", "tilt.Lc"]
    assert [v.kind for v in machine.decision_variables] == ["hinge_distance", "piston_offset", "rod_length"] * 2


def test_machine_file_equals_the_converted_crane_file(machine: Machine, crane: Crane) -> None:
    """Every number of the machine file equals the converter's from hiab_xs031.yaml (to 1e-15)."""
    converted = machine_from_crane(crane)
    np.testing.assert_allclose(machine.design_values(), crane.default_lengths.as_array(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(machine.design_values(), converted.design_values(), rtol=0, atol=1e-15)
    for a, b in zip(machine.links, converted.links, strict=True):
        assert (a.name, a.parent, a.joint, a.joint_kind) == (b.name, b.parent, b.joint, b.joint_kind)
        np.testing.assert_allclose(a.joint_frame.matrix, b.joint_frame.matrix, rtol=0, atol=1e-15)
        body_a, body_b = a.body, b.body
        assert (body_a is None) == (body_b is None)
        if body_a is not None and body_b is not None:
            assert body_a.mass == pytest.approx(body_b.mass, rel=1e-15)
            np.testing.assert_allclose(body_a.com, body_b.com, rtol=0, atol=1e-14)
            np.testing.assert_allclose(body_a.inertia, body_b.inertia, rtol=0, atol=1e-12)
    np.testing.assert_allclose(machine.tcp.matrix, converted.tcp.matrix, rtol=0, atol=1e-15)


def test_closure_reproduces_crane_mechanism_on_random_states(machine: Machine, crane: Crane) -> None:
    """x, dx, ddx and the inverse map agree with crane/mechanism.py to 1e-12 for random designs and states."""
    rng = np.random.default_rng(7)
    for values in _random_lengths(rng, 5):
        designed = machine.with_design(values)
        lengths = LinkLengths.from_array(values)
        q = _random_joints(machine, rng, 400)
        for k, (old, new) in enumerate(zip(crane.chains, designed.chains[:2], strict=True)):
            xi = getattr(lengths, old.name)
            dq, ddq = rng.normal(size=400), rng.normal(size=400)
            expected = mechanism.joint_to_actuator(old, xi, q[:, k], dq, ddq)
            got = closure.joint_to_actuator(designed, new, q[:, k], dq, ddq)
            for e, g in zip(expected, got, strict=True):
                np.testing.assert_allclose(g, e, rtol=0, atol=1e-12)
            back = closure.actuator_to_joint(designed, new, *expected)
            want = mechanism.actuator_to_joint(old, xi, *expected)
            for e, g in zip(want, back, strict=True):
                np.testing.assert_allclose(g, e, rtol=0, atol=1e-12)


def test_kinematics_reproduce_crane_kinematics_on_random_states(machine: Machine, crane: Crane) -> None:
    """Every link, actuator body and the TCP sit where crane/kinematics.py puts them, to 1e-12, for random designs."""
    rng = np.random.default_rng(11)
    for values in _random_lengths(rng, 3):
        designed = machine.with_design(values)
        q = _random_joints(machine, rng, 300)
        old = crane_kinematics.forward_kinematics(crane, LinkLengths.from_array(values), q[:, 0], q[:, 1], q[:, 2])
        new = forward_kinematics(designed, q)
        for link in designed.link_names:
            np.testing.assert_allclose(new.rotation[link], old.rotation[link], rtol=0, atol=1e-12)
            np.testing.assert_allclose(new.position[link], old.position[link], rtol=0, atol=1e-12)
        np.testing.assert_allclose(new.tcp_position, old.position["tcp"], rtol=0, atol=1e-12)
        np.testing.assert_allclose(new.tcp_rotation, old.rotation["tcp"], rtol=0, atol=1e-12)
        for chain in ("lift", "tilt"):
            for part in ("cylinder", "rod"):
                rotation, position = new.bodies[(chain, part)]
                np.testing.assert_allclose(rotation, old.rotation[f"{chain}_{part}"], rtol=0, atol=1e-12)
                np.testing.assert_allclose(position, old.position[f"{chain}_{part}"], rtol=0, atol=1e-12)
            np.testing.assert_allclose(new.stroke[chain], old.stroke[chain], rtol=0, atol=1e-12)


def test_design_scales_actuator_bodies_as_the_crane_does(machine: Machine, crane: Crane) -> None:
    """with_design rescales cylinder and rod bodies exactly as Crane.bodies_for (slender rule)."""
    values = np.array([1.1, 0.12, 0.8, 1.0, 0.06, 0.7])
    designed = machine.with_design(values)
    old = {b.name: b for b in crane.bodies_for(LinkLengths.from_array(values))}
    for chain in designed.chains[:2]:
        for part, body in (("cylinder", chain.actuator.cylinder_body), ("rod", chain.actuator.rod_body)):
            assert body is not None
            want = old[f"{chain.name}_{part}"]
            assert body.mass == pytest.approx(want.mass, rel=1e-14)
            np.testing.assert_allclose(body.com, want.com, rtol=1e-14)
            np.testing.assert_allclose(body.inertia, want.inertia, rtol=1e-14)
    np.testing.assert_allclose(designed.design_values(), values, rtol=0, atol=1e-15)


def test_reachable_range_and_usable_stroke_match_the_crane(machine: Machine, crane: Crane) -> None:
    """The reachable joint range found by scanning equals crane/mechanism.py's closed form to 1e-12."""
    from hiab_sim.machine.kinematics.assembly import reachable_joint_range

    for old, new in zip(crane.chains, machine.chains[:2], strict=True):
        want = mechanism.reachable_joint_range(old, old.default_lengths)
        got = reachable_joint_range(machine, new)
        assert got is not None
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)

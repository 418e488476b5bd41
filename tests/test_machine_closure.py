"""Loop closure of any chain: closed form against the generic Newton closure and finite differences."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.crane.description import Crane
from hiab_sim.machine.description import Machine
from hiab_sim.machine.kinematics import closure
from hiab_sim.machine.kinematics.closure_numeric import numeric_closure
from hiab_sim.machine.kinematics.forward import forward_kinematics, pin_positions
from hiab_sim.machine.loader import load_machine, machine_from_dict

MACHINES = ("xs031", "exact")


@pytest.fixture(scope="module", params=MACHINES)
def machine(request: pytest.FixtureRequest) -> Machine:
    """Each shipped machine."""
    return load_machine(request.param)


def _wrap(a: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * a))


def _joint_samples(machine: Machine, joint: str, n: int, seed: int) -> np.ndarray:
    low, high = machine.joint_link(joint).joint_range  # type: ignore[misc]
    return np.random.default_rng(seed).uniform(low, high, n)


def test_closed_form_and_newton_closure_agree(machine: Machine) -> None:
    """s, s', s'' and every body angle with its derivatives agree between the two closures to 1e-12."""
    for k, chain in enumerate(machine.chains):
        q = _joint_samples(machine, chain.joint, 500, k)
        a, b = closure.closure(machine, chain, q), numeric_closure(machine, chain, q)
        assert np.all(a.closes) and np.all(b.closes)
        for field in ("length", "length_dq", "length_dq2"):
            np.testing.assert_allclose(getattr(b, field), getattr(a, field), rtol=0, atol=1e-12)
        assert set(a.angles) == set(b.angles)
        for name in a.angles:
            np.testing.assert_allclose(_wrap(b.angles[name] - a.angles[name]), 0.0, atol=1e-12)
            np.testing.assert_allclose(b.angles_dq[name], a.angles_dq[name], rtol=0, atol=1e-11)
            np.testing.assert_allclose(b.angles_dq2[name], a.angles_dq2[name], rtol=0, atol=1e-10)


def test_closure_derivatives_match_central_differences(machine: Machine) -> None:
    """ds/dq and d2s/dq2 (and the body angles') equal central differences of the closure itself."""
    h = 1e-5
    for k, chain in enumerate(machine.chains):
        q = _joint_samples(machine, chain.joint, 50, 10 + k) * 0.98
        c = closure.closure(machine, chain, q)
        plus, minus = closure.closure(machine, chain, q + h), closure.closure(machine, chain, q - h)
        np.testing.assert_allclose(c.length_dq, (plus.length - minus.length) / (2 * h), rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(c.length_dq2, (plus.length_dq - minus.length_dq) / (2 * h), rtol=1e-6, atol=1e-8)
        second = (plus.length - 2 * c.length + minus.length) / h**2
        np.testing.assert_allclose(c.length_dq2, second, rtol=1e-3, atol=1e-4)
        for name in c.angles:
            fd = _wrap(plus.angles[name] - minus.angles[name]) / (2 * h)
            np.testing.assert_allclose(c.angles_dq[name], fd, rtol=1e-7, atol=1e-9)
            fd2 = (plus.angles_dq[name] - minus.angles_dq[name]) / (2 * h)
            np.testing.assert_allclose(c.angles_dq2[name], fd2, rtol=1e-6, atol=1e-8)


def test_stroke_to_joint_inverts_joint_to_stroke(machine: Machine) -> None:
    """The map joint -> stroke -> joint is the identity over the working range, and the time maps invert each other."""
    rng = np.random.default_rng(3)
    for chain in machine.chains:
        q = _joint_samples(machine, chain.joint, 300, 5)
        x = closure.joint_to_stroke(machine, chain, q)
        np.testing.assert_allclose(closure.stroke_to_joint(machine, chain, x), q, rtol=0, atol=1e-11)
        dq, ddq = rng.normal(size=300), rng.normal(size=300)
        back = closure.actuator_to_joint(machine, chain, *closure.joint_to_actuator(machine, chain, q, dq, ddq))
        for want, got in zip((q, dq, ddq), back, strict=True):
            np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-10)


def test_actuator_length_is_the_distance_between_its_pins(machine: Machine) -> None:
    """Independently of the closure: the actuator's pins are x0 + x apart; rocker and coupler keep their lengths."""
    rng = np.random.default_rng(4)
    ranges = [machine.joint_link(j).joint_range for j in machine.joint_names]
    q = np.stack([rng.uniform(lo, hi, 200) for lo, hi in ranges], -1)  # type: ignore[misc]
    frames = forward_kinematics(machine, q)
    for chain in machine.chains:
        if chain.kind == "direct":
            continue
        pins = pin_positions(machine, frames, chain.name)
        end = pins["pin"] if chain.kind == "linkage" else pins["end"]
        x0 = chain.actuator.retracted_length
        assert x0 is not None
        np.testing.assert_allclose(
            np.linalg.norm(end - pins["base"], axis=-1), x0 + frames.stroke[chain.name], atol=1e-12
        )
        _, rod_origin = frames.bodies[(chain.name, "rod")]
        rod_end = np.linalg.norm(rod_origin - pins["base"], axis=-1) + chain.actuator.rod_length
        np.testing.assert_allclose(rod_end, x0 + frames.stroke[chain.name], atol=1e-12)
        if chain.kind == "linkage" and chain.linkage is not None:
            np.testing.assert_allclose(
                np.linalg.norm(pins["pin"] - pins["rocker"], axis=-1), chain.linkage.rocker_length
            )
            np.testing.assert_allclose(
                np.linalg.norm(pins["pin"] - pins["coupler"], axis=-1), chain.linkage.coupler_length
            )


def _four_bar(
    rocker: tuple[float, float], coupler: tuple[float, float], lengths: tuple[float, float], side: int
) -> Machine:
    """A two-link machine whose second joint is driven through a four-bar of the given geometry."""
    return machine_from_dict(
        {
            "name": "four-bar",
            "source": "test",
            "gravity": 9.81,
            "links": {
                "ground": {},
                "stick": {
                    "parent": "ground",
                    "joint": "j1",
                    "kind": "revolute",
                    "joint_range": [-0.5, 0.5],
                    "bodies": {"s": {"mass": 10.0, "com": [0.5, 0.0], "inertia_zz": 1.0}},
                },
                "tool": {
                    "parent": "stick",
                    "joint": "j2",
                    "kind": "revolute",
                    "joint_frame": {"r": [1.0, 0.0]},
                    "joint_range": [-0.2, 0.2],
                    "bodies": {"t": {"mass": 5.0, "com": [0.2, 0.0], "inertia_zz": 0.1}},
                },
            },
            "chains": {
                "c1": {
                    "kind": "triangle",
                    "joint": "j1",
                    "pivots": {
                        "base": {"link": "ground", "position": [0.3, -0.3]},
                        "end": {"link": "stick", "position": [0.5, 0.1]},
                    },
                    "actuator": {"stroke": 1.0, "piston_offset": 0.05, "rod_length": 0.3, "emla": "e1"},
                },
                "c2": {
                    "kind": "linkage",
                    "joint": "j2",
                    "pivots": {
                        "base": {"link": "stick", "position": [0.2, 0.25]},
                        "rocker": {"link": "stick", "position": list(rocker)},
                        "coupler": {"link": "tool", "position": list(coupler)},
                    },
                    "linkage": {"rocker_length": lengths[0], "coupler_length": lengths[1], "pin_side": side},
                    "actuator": {"stroke": 2.0, "piston_offset": 0.05, "rod_length": 0.2, "emla": "e2"},
                },
            },
            "tcp": {"link": "tool", "r": [0.4, 0.0]},
        },
        check_assembly=False,
    )


@settings(max_examples=40, deadline=None)
@given(
    rx=st.floats(0.7, 0.9),
    ry=st.floats(-0.05, 0.05),
    cx=st.floats(-0.05, 0.05),
    cy=st.floats(0.1, 0.2),
    lr=st.floats(0.2, 0.3),
    lc=st.floats(0.2, 0.3),
    side=st.sampled_from([1, -1]),
    q=st.floats(-0.2, 0.2),
)
def test_four_bar_closures_agree_for_any_geometry(
    rx: float, ry: float, cx: float, cy: float, lr: float, lc: float, side: int, q: float
) -> None:
    """For random four-bars that assemble, the closed form and Newton agree and H lies on pin_side."""
    machine = _four_bar((rx, ry), (cx, cy), (lr, lc), side)
    chain = machine.chain("c2")
    a = closure.closure(machine, chain, np.array([q]))
    if not a.closes[0] or abs(a.length_dq[0]) < 1e-3:
        return
    geo = closure.chain_geometry(machine, chain)
    H, _, u, _ = closure.pin_position(geo, np.array([q]))
    r = geo.fixed["rocker"]
    assert np.sign(u[0, 0] * (H[0, 1] - r[1]) - u[0, 1] * (H[0, 0] - r[0])) == side
    b = numeric_closure(machine, chain, np.array([q]))
    assert b.closes[0]
    np.testing.assert_allclose([b.length[0], b.length_dq[0]], [a.length[0], a.length_dq[0]], rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(b.length_dq2[0], a.length_dq2[0], rtol=1e-7, atol=1e-9)


def test_reversed_triangle_mounting_gives_the_same_lengths(machine: Machine) -> None:
    """Swapping an actuator's ends (cylinder on the driven link) leaves s(q), its ratios and the inverse unchanged.

    The cylinder then points the other way: its angle turns by pi. Checked for every triangle of each
    machine, on both closures.
    """
    import dataclasses

    for chain in machine.chains:
        if chain.kind != "triangle":
            continue
        base, end = chain.pivot("base"), chain.pivot("end")
        flipped = dataclasses.replace(
            chain,
            pivots=(dataclasses.replace(end, role="base"), dataclasses.replace(base, role="end")),
            variables=(),
        )
        other = dataclasses.replace(machine, chains=tuple(flipped if c is chain else c for c in machine.chains))
        q = _joint_samples(machine, chain.joint, 200, 21)
        a, b = closure.closure(machine, chain, q), closure.closure(other, flipped, q)
        np.testing.assert_allclose(b.length, a.length, atol=1e-13)
        np.testing.assert_allclose(b.length_dq, a.length_dq, atol=1e-13)
        np.testing.assert_allclose(b.length_dq2, a.length_dq2, atol=1e-12)
        np.testing.assert_allclose(_wrap(b.angles["cylinder"] - a.angles["cylinder"] - np.pi), 0.0, atol=1e-12)
        n = numeric_closure(other, flipped, q)
        np.testing.assert_allclose(n.length_dq2, b.length_dq2, atol=1e-12)
        x = closure.joint_to_stroke(other, flipped, q)
        np.testing.assert_allclose(closure.stroke_to_joint(other, flipped, x), q, atol=1e-11)


def test_design_partials_match_the_crane_and_finite_differences(machine: Machine, crane: Crane) -> None:
    """The stroke's design partials at fixed q equal the crane's and central differences of with_design.

    On the XS 031: crane/mechanism.py's dx/d(L, Lc0, Lc) to 1e-12; on every chain with variables
    (the excavator's pivot x/y and retracted length included): central differences.
    """
    from hiab_sim.crane import mechanism
    from hiab_sim.machine.kinematics.design_partials import stroke_design_partials

    values = machine.design_values()
    keys = machine.variable_keys
    for chain in machine.chains:
        q = _joint_samples(machine, chain.joint, 40, 31)
        dx_dq, dx_dv = stroke_design_partials(machine, chain, q)
        np.testing.assert_allclose(dx_dq, closure.closure(machine, chain, q).length_dq, rtol=0, atol=0)
        if machine.name == crane.name and chain.kind == "triangle":
            old = getattr(crane, chain.name)
            want_q, want_xi = mechanism.joint_to_stroke_partials(old, old.default_lengths, q)
            np.testing.assert_allclose(dx_dq, want_q, rtol=0, atol=1e-12)
            np.testing.assert_allclose(dx_dv, want_xi, rtol=0, atol=1e-12)
        for k, variable in enumerate(chain.variables):
            j = keys.index(variable.key)
            h = 1e-6
            plus, minus = values.copy(), values.copy()
            plus[j] += h
            minus[j] -= h
            up_machine = machine.with_design(plus, check_bounds=False)
            down_machine = machine.with_design(minus, check_bounds=False)
            up = closure.joint_to_stroke(up_machine, up_machine.chain(chain.name), q)
            down = closure.joint_to_stroke(down_machine, down_machine.chain(chain.name), q)
            np.testing.assert_allclose(dx_dv[:, k], (up - down) / (2 * h), rtol=1e-7, atol=1e-9)


def test_four_bar_pivot_partials_match_finite_differences() -> None:
    """Moving the bucket four-bar's rocker or coupler pivot: the analytic dx/dv equals central differences."""
    import dataclasses

    from hiab_sim.machine.description import DecisionVariable
    from hiab_sim.machine.kinematics.design_partials import stroke_design_partials

    base = load_machine("exact")
    bucket = base.chain("bucket")
    sets = (
        (
            DecisionVariable("bucket", "Jx", "pivot_x", "rocker", 0.7, 1.0),
            DecisionVariable("bucket", "Jy", "pivot_y", "rocker", -0.1, 0.1),
            DecisionVariable("bucket", "Kx", "pivot_x", "coupler", -0.1, 0.1),
        ),
        (DecisionVariable("bucket", "Kd", "hinge_distance", "coupler", 0.1, 0.2),),
    )
    h = 1e-6
    for extra in sets:
        chain = dataclasses.replace(bucket, variables=extra)
        machine = dataclasses.replace(base, chains=tuple(chain if c is bucket else c for c in base.chains))
        q = _joint_samples(machine, chain.joint, 40, 41) * 0.95
        _, dx_dv = stroke_design_partials(machine, chain, q)
        values = machine.design_values()
        offset = machine.variable_keys.index(extra[0].key)
        for k in range(len(extra)):
            plus, minus = values.copy(), values.copy()
            plus[offset + k] += h
            minus[offset + k] -= h
            up, down = machine.with_design(plus), machine.with_design(minus)
            x_up = closure.joint_to_stroke(up, up.chain("bucket"), q)
            x_down = closure.joint_to_stroke(down, down.chain("bucket"), q)
            np.testing.assert_allclose(dx_dv[:, k], (x_up - x_down) / (2 * h), rtol=1e-6, atol=1e-9)
            assert np.max(np.abs(dx_dv[:, k])) > 1e-3  # the pivot matters


def test_length_and_rate_are_the_full_closures_numbers_bit_for_bit(machine: Machine) -> None:
    """The stroke rows' light closure gives s, s' (and a four-bar's pin) equal to the full closure's, bit for bit."""
    for k, chain in enumerate(machine.chains):
        q = np.random.default_rng(k).uniform(-np.pi, np.pi, 400)
        geo = closure.chain_geometry(machine, chain)
        # a four-bar with its rocker shortened by a third, which cannot close over part of the turn
        short = dataclasses.replace(geo, rocker_length=geo.rocker_length * 2.0 / 3.0)
        for g in (geo, short) if chain.kind == "linkage" else (geo,):
            with np.errstate(invalid="ignore", divide="ignore"):
                full = closure.geometry_closure(g, q)
                light = closure.length_and_rate(g, q)
            np.testing.assert_array_equal(light.length, full.length)
            np.testing.assert_array_equal(light.length_dq, full.length_dq)
            if g is short:
                assert not np.all(full.closes)  # the samples where it cannot close are compared too
            if chain.kind == "linkage":
                with np.errstate(invalid="ignore", divide="ignore"):
                    pin, _, _, _ = closure.pin_position(g, q)
                np.testing.assert_array_equal(light.pin, pin)

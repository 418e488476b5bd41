"""Pin forces: the MuJoCo and the analytic path agree, every link balances at rest, a hand free-body check."""

from __future__ import annotations

import numpy as np
import pytest

from hiab_sim.crane.description import Crane
from hiab_sim.crane.kinematics import Frames, forward_kinematics
from hiab_sim.dynamics import JointSamples
from hiab_sim.structure.pin_loads import PinLoads
from hiab_sim.structure.pin_paths import pin_loads

PAYLOAD_KG = 200.0


def _random_states(crane: Crane, n: int, seed: int) -> JointSamples:
    rng = np.random.default_rng(seed)
    lo = np.array([crane.lift.joint_range[0], crane.tilt.joint_range[0], 0.0])
    hi = np.array([crane.lift.joint_range[1], crane.tilt.joint_range[1], crane.telescope.stroke])
    q = lo + (hi - lo) * rng.uniform(0.05, 0.95, size=(n, 3))
    return JointSamples(q, rng.normal(scale=0.4, size=(n, 3)), rng.normal(scale=1.5, size=(n, 3)))


def test_both_id_paths_give_the_same_pin_forces(crane: Crane) -> None:
    """Random moving states with a TCP force: MuJoCo's and the analytic pin forces agree to 1e-9 relative."""
    joints = _random_states(crane, 12, seed=4)
    tcp = np.array([300.0, -PAYLOAD_KG * crane.gravity, 0.0])
    a = pin_loads(crane, None, joints, "analytic", tcp_force=tcp)
    b = pin_loads(crane, None, joints, "mujoco", tcp_force=tcp)
    scale = np.max(a.magnitude, axis=0)
    assert np.max(np.abs(a.force_world - b.force_world) / scale[None, :, None]) < 1e-9
    assert np.max(np.abs(a.force_local - b.force_local) / scale[None, :, None]) < 1e-9
    np.testing.assert_allclose(a.magnitude, np.hypot(*np.moveaxis(a.force_local, -1, 0)), rtol=1e-12)


def _groups(crane: Crane) -> dict[str, tuple[str, ...]]:
    """Bodies held together by slides (no pin between them): each boom with what slides on it, each actuator."""
    groups = {f"{c.name}_boom": (f"{c.name}_boom",) for c in crane.chains}
    groups[crane.telescope.parent] = (crane.telescope.parent, "telescope_rod")
    for c in crane.chains:
        groups[f"{c.name} actuator"] = (f"{c.name}_cylinder", f"{c.name}_rod")
    return groups


def _pin_points(crane: Crane, frames: Frames) -> dict[str, np.ndarray]:
    out = {}
    for c in crane.chains:
        out[f"{c.name}.base_pivot"] = frames.position[f"{c.name}_cylinder"]
        out[f"{c.name}.boom_hinge"] = frames.position[f"{c.name}_boom"]
        out[f"{c.name}.rod_end"] = frames.point(f"{c.name}_boom", [c.L1, 0.0, 0.0])
    return out


def _cross_z(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


GROUPS = ["lift_boom", "tilt_boom", "lift actuator", "tilt actuator"]


@pytest.mark.parametrize("group", GROUPS)
def test_pin_forces_and_gravity_balance_each_link_at_rest(crane: Crane, group: str) -> None:
    """At rest, the pin forces on a link (and the bodies sliding on it) cancel its weight: forces and moments."""
    rng = np.random.default_rng(7)
    lo = np.array([crane.lift.joint_range[0], crane.tilt.joint_range[0], 0.0])
    hi = np.array([crane.lift.joint_range[1], crane.tilt.joint_range[1], crane.telescope.stroke])
    q = lo + (hi - lo) * rng.uniform(0.05, 0.95, size=(6, 3))
    tcp = np.array([0.0, -PAYLOAD_KG * crane.gravity, 0.0])
    loads = pin_loads(crane, None, JointSamples.at_rest(q), "mujoco", tcp_force=tcp)
    frames = forward_kinematics(crane, crane.default_lengths, *q.T)
    members = _groups(crane)[group]
    force = np.zeros((6, 2))
    moment = np.zeros(6)
    points = _pin_points(crane, frames)
    for k, pin in enumerate(loads.pins):
        on_bracket = loads.force_world[:, k]
        sign = 1.0 if pin.bracket in members else (-1.0 if pin.member in members else 0.0)
        if sign != 0.0 and not (pin.bracket in members and pin.member in members):
            force += sign * on_bracket
            moment += _cross_z(points[pin.name], sign * on_bracket)
    weight = 0.0
    for body in crane.bodies_for(crane.default_lengths):
        if body.link in members:
            w = np.array([0.0, -body.mass * crane.gravity])
            weight += body.mass * crane.gravity
            force += w
            moment += _cross_z(frames.point(body.link, body.com), w)
    if "telescope_rod" in members:
        force += tcp[:2]
        moment += _cross_z(frames.position["tcp"], tcp[:2])
        weight += PAYLOAD_KG * crane.gravity
    assert np.max(np.abs(force)) < 1e-9 * weight
    assert np.max(np.abs(moment)) < 1e-9 * weight * 3.0


def test_lift_rod_end_pin_matches_a_hand_free_body_calculation(crane: Crane) -> None:
    """Static pose with a payload: the rod-end pin force from two moment balances written out by hand.

    The lift actuator (cylinder + rod) hangs between its base pivot Bc and the pin Tc, so its
    weights' moment about Bc is carried by -P at Tc; the lift boom with everything it carries
    (tilt boom, tilt actuator, telescope rod, payload) turns about the hinge B1 and is held by P.
    """
    q = np.array([[0.6, -1.2, 0.7]])
    g = crane.gravity
    frames = forward_kinematics(crane, crane.default_lengths, *q.T)
    bodies = crane.bodies_for(crane.default_lengths)

    def weight_moment(links: set[str], about: np.ndarray) -> float:
        total = 0.0
        for body in bodies:
            if body.link in links:
                c = frames.point(body.link, body.com)[0]
                total += (c[0] - about[0]) * (-body.mass * g)  # r x (0, -m g): -m g r_x
        return total

    bc = frames.position["lift_cylinder"][0]
    b1 = frames.position["lift_boom"][0]
    tc = frames.point("lift_boom", [crane.lift.L1, 0.0, 0.0])[0]
    tcp = frames.position["tcp"][0]
    m_pair = weight_moment({"lift_cylinder", "lift_rod"}, bc)
    carried = {"lift_boom", "tilt_boom", "tilt_cylinder", "tilt_rod", "telescope_rod"}
    m_boom = weight_moment(carried, b1) + (tcp[0] - b1[0]) * (-PAYLOAD_KG * g)
    # (Tc - Bc) x (-P) + m_pair = 0 and (Tc - B1) x P + m_boom = 0, with r x P = r_x P_y - r_y P_x
    a1, a2 = tc - bc, tc - b1
    system = np.array([[a1[1], -a1[0]], [-a2[1], a2[0]]])
    hand = np.linalg.solve(system, np.array([-m_pair, -m_boom]))
    loads: PinLoads = pin_loads(crane, None, JointSamples.at_rest(q), "analytic", tcp_force=[0.0, -PAYLOAD_KG * g, 0.0])
    k = [p.name for p in loads.pins].index("lift.rod_end")
    np.testing.assert_allclose(loads.force_world[0, k], hand, rtol=1e-10)
    assert np.linalg.norm(hand) > 3e4  # a real load: tens of kN


def test_vector_range_covers_the_magnitude_range(crane: Crane) -> None:
    """The largest change of a pin's force vector is never below the change of its magnitude."""
    loads = pin_loads(crane, None, _random_states(crane, 20, seed=9), "analytic")
    vector, magnitude = loads.vector_range(), loads.magnitude_range()
    assert all(vector[name] >= magnitude[name] - 1e-9 for name in vector)
    name, peak = loads.most_loaded()
    assert peak == max(loads.peak().values()) and name in loads.peak()


def test_pins_on_the_base_carry_the_whole_moving_weight_at_rest(crane: Crane) -> None:
    """At rest, the forces the base's pins receive add up to the weight of every moving body and the payload."""
    q = np.array([[0.3, -1.6, 0.2], [1.1, -0.4, 0.9]])
    tcp = np.array([0.0, -PAYLOAD_KG * crane.gravity, 0.0])
    loads = pin_loads(crane, None, JointSamples.at_rest(q), "mujoco", tcp_force=tcp)
    frames = forward_kinematics(crane, crane.default_lengths, *q.T)
    points = _pin_points(crane, frames)
    on_base = [k for k, pin in enumerate(loads.pins) if pin.bracket == "base"]
    force = sum(loads.force_world[:, k] for k in on_base)
    moment = sum(_cross_z(points[loads.pins[k].name], loads.force_world[:, k]) for k in on_base)
    weight = np.zeros(2)
    weight_moment = np.zeros(2)
    for body in crane.bodies_for(crane.default_lengths):
        if body.link != "base":
            w = np.array([0.0, -body.mass * crane.gravity])
            weight = weight + w
            weight_moment = weight_moment + _cross_z(frames.point(body.link, body.com), w)
    weight = weight + tcp[:2]
    weight_moment = weight_moment + _cross_z(frames.position["tcp"], tcp[:2])
    np.testing.assert_allclose(force, np.broadcast_to(weight, force.shape), rtol=1e-10, atol=1e-6)
    np.testing.assert_allclose(moment, weight_moment, rtol=1e-10, atol=1e-6)

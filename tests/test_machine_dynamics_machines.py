"""Machines the dynamics tests run on, and a check that the excavator below closes like its source.

* ``excavator()``: the eXact excavator arm of ``shared/reference/exact-excavator-arm.yaml`` (boom and
  arm triangles, bucket four-bar), written here from the reference's figures as a test machine (not
  the preset). The source publishes no actuator, rocker or link bodies; the values below are
  this test's choices (a 15 kg housing and a 6 kg rod per EMLA, 3 kg rocker and link), chosen
  only so that every body has a mass.
* ``hand_machine()``: one horizontal boom on a hinge, lifted by a vertical actuator, for a
  free-body calculation by hand.
* ``random_states(machine, ...)``: joint samples inside the working ranges.
"""

from __future__ import annotations

import numpy as np

from hiab_sim.machine.chains import Actuator, Chain, Linkage, Pivot
from hiab_sim.machine.description import Link, Machine
from hiab_sim.machine.dynamics.newton_euler import NewtonEulerInverseDynamics
from hiab_sim.machine.parts import Pose, RigidBody

#: Retracted pin-to-pin lengths [m]: the reference's lengths at the joint ends that retract each EMLA.
EXCAVATOR_X0 = {"boom": 0.90501, "arm": 1.04600, "bucket": 0.84000}
#: Strokes the joint limits need (reference: boom 0.400, arm 0.510, bucket 0.420 m), plus 5 mm.
EXCAVATOR_STROKE = {"boom": 0.405, "arm": 0.515, "bucket": 0.425}


def _planar_body(name: str, mass: float, com: tuple[float, float], izz: float) -> RigidBody:
    return RigidBody(name, mass, (com[0], com[1], 0.0), ((izz / 2, 0, 0), (0, izz / 2, 0), (0, 0, izz)), True)


def _slender(name: str, mass: float, length: float) -> RigidBody:
    """A uniform rod along x from 0 to ``length``: com at length / 2, I = m l^2 / 12 transverse."""
    transverse = mass * length**2 / 12.0
    axial = mass * 0.03**2 / 2.0
    return RigidBody(name, mass, (length / 2, 0.0, 0.0), ((axial, 0, 0), (0, transverse, 0), (0, 0, transverse)))


def _actuator(name: str, x0: float, stroke: float) -> Actuator:
    piston = 0.12  # m, this test's choice of Lc0
    return Actuator(
        stroke=stroke,
        piston_offset=piston,
        rod_length=x0 - piston,
        emla=name,
        cylinder_body=_slender(f"{name}_housing", 15.0, x0),
        rod_body=_slender(f"{name}_rod", 6.0, x0 - piston),
    )


def excavator(mount: Pose | None = None) -> Machine:
    """The eXact arm from the reference sheet's points, lengths and bodies (see the module docstring).

    ``mount``: the chassis frame in the world (default: the world itself), e.g. a machine on a slope.
    """
    links = (
        Link("chassis", None, "mount", "fixed", mount or Pose((0.0, 0.0, 0.0)), None, ()),
        Link("boom", "chassis", "alpha", "revolute", Pose((0.0, 0.0, 0.0)), (-0.4737, 1.0923),
             (_planar_body("boom", 227.343, (1.025, 0.384), 67.768),)),
        Link("arm", "boom", "beta", "revolute", Pose((2.050, 0.0, 0.0)), (-2.5848, -0.5103),
             (_planar_body("arm", 130.123, (0.225, 0.227), 30.258),)),
        Link("bucket", "arm", "gamma", "revolute", Pose((1.050, 0.0, 0.0)), (-2.8659, 0.7839),
             (_planar_body("bucket", 53.000, (0.289, 0.166), 3.021),)),
    )  # fmt: skip
    chains = (
        Chain("boom", "triangle", "alpha", _actuator("boom", EXCAVATOR_X0["boom"], EXCAVATOR_STROKE["boom"]),
              (Pivot("base", "chassis", (0.135, -0.264, 0.0)), Pivot("end", "boom", (1.025, 0.278, 0.0)))),
        Chain("arm", "triangle", "beta", _actuator("arm", EXCAVATOR_X0["arm"], EXCAVATOR_STROKE["arm"]),
              (Pivot("base", "boom", (0.977, 0.737, 0.0)), Pivot("end", "arm", (-0.251, 0.158, 0.0)))),
        Chain("bucket", "linkage", "gamma",
              _actuator("bucket", EXCAVATOR_X0["bucket"], EXCAVATOR_STROKE["bucket"]),
              (Pivot("base", "arm", (-0.134, 0.320, 0.0)), Pivot("rocker", "arm", (0.880, 0.0, 0.0)),
               Pivot("coupler", "bucket", (-0.014, 0.164, 0.0))),
              Linkage(0.240, 0.240, 1, _slender("rocker", 3.0, 0.240), _slender("link", 3.0, 0.240))),
    )  # fmt: skip
    return Machine(
        name="eXact arm (test machine)",
        source="shared/reference/exact-excavator-arm.yaml",
        gravity=9.81,
        links=links,
        chains=chains,
        tcp_link="bucket",
        tcp=Pose((0.567, 0.0, 0.0)),
    )


#: Hand machine: hinge at the origin, end pivot at (A, 0) on the boom, base pivot H below it [m].
HAND_A, HAND_H = 0.8, 0.6
#: Boom mass [kg] and centre of mass (C, D) [m]; cylinder and rod masses [kg] (com on the axis).
HAND_M, HAND_C, HAND_D = 120.0, 1.1, 0.15
HAND_MC, HAND_MR = 9.0, 4.0


def hand_machine(reversed_actuator: bool = False) -> Machine:
    """A boom along +x at q = 0, hinged at the origin, held by a vertical actuator from (A, -H) to (A, 0).

    ``reversed_actuator``: the cylinder hangs on the boom at (A, 0) and the rod is pinned to the ground
    at (A, -H) (a triangle whose base pivot is on the driven link).
    """
    actuator = Actuator(
        stroke=0.3,
        piston_offset=0.1,
        rod_length=0.4,  # x0 = 0.5 m: at q = 0 the stroke is H - x0 = 0.1 m
        emla="act",
        cylinder_body=RigidBody("housing", HAND_MC, (0.25, 0.0, 0.0), ((0.01, 0, 0), (0, 0.2, 0), (0, 0, 0.2))),
        rod_body=RigidBody("rod", HAND_MR, (0.2, 0.0, 0.0), ((0.005, 0, 0), (0, 0.06, 0), (0, 0, 0.06))),
    )
    boom = RigidBody("boom", HAND_M, (HAND_C, HAND_D, 0.0), ((2.0, 0, 0), (0, 20.0, 0), (0, 0, 21.0)))
    pivots = (Pivot("base", "ground", (HAND_A, -HAND_H, 0.0)), Pivot("end", "beam", (HAND_A, 0.0, 0.0)))
    if reversed_actuator:
        pivots = (Pivot("base", "beam", (HAND_A, 0.0, 0.0)), Pivot("end", "ground", (HAND_A, -HAND_H, 0.0)))
    return Machine(
        name="hand",
        source="test",
        gravity=9.81,
        links=(
            Link("ground", None, "mount", "fixed", Pose((0.0, 0.0, 0.0)), None, ()),
            Link("beam", "ground", "hinge", "revolute", Pose((0.0, 0.0, 0.0)), (-0.3, 0.3), (boom,)),
        ),
        chains=(Chain("act", "triangle", "hinge", actuator, pivots),),
        tcp_link="beam",
        tcp=Pose((2.0, 0.0, 0.0)),
    )


def joint_limits(machine: Machine) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper working range of every joint, in joint order."""
    ranges = np.array([machine.joint_link(j).joint_range for j in machine.joint_names])
    return ranges[:, 0], ranges[:, 1]


def random_states(machine: Machine, samples: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random joint positions inside 2-98 % of the working ranges, rates ~0.5/s and accelerations ~1/s^2."""
    rng = np.random.default_rng(seed)
    low, high = joint_limits(machine)
    n = len(low)
    q = low + (high - low) * rng.uniform(0.02, 0.98, (samples, n))
    return q, rng.normal(0.0, 0.5, (samples, n)), rng.normal(0.0, 1.0, (samples, n))


def test_excavator_actuator_lengths_match_the_source_fits() -> None:
    """Pin-to-pin lengths from the closure equal the source's polynomial fits within 1e-3 m (reference sheet).

    This checks the four-bar closure (pin H on the +n side of J -> K) against published numbers.
    """
    machine = excavator()
    dynamics = NewtonEulerInverseDynamics(machine)
    checks = {
        "boom": (0, [-0.4737, 0.0, 1.0923], [0.90501, 1.04205, 1.30500]),
        "arm": (1, [-2.5848, -1.5, -0.5103], [1.55600, 1.30271, 1.04600]),
        "bucket": (2, [-2.8659, -1.0, 0.0, 0.7839], [1.26000, 1.11147, 0.94316, 0.84000]),
    }
    mid = np.array([0.3, -1.5, -1.0])
    for k, (name, (column, angles, lengths)) in enumerate(checks.items()):
        q = np.tile(mid, (len(angles), 1))
        q[:, column] = angles
        zero = np.zeros_like(q)
        stroke = dynamics(q, zero, zero).stroke[:, k]
        np.testing.assert_allclose(stroke + EXCAVATOR_X0[name], lengths, atol=1e-3, err_msg=name)

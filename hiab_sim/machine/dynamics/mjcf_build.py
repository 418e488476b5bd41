"""MJCF model of any machine for one design, built with :class:`mujoco.MjSpec` from its description.

:func:`build_machine_spec` adds the bodies of :func:`hiab_sim.machine.dynamics.tree.machine_tree`
to the shared template ``assets/mjcf/crane_template.xml`` (materials, lights, cameras, floor,
options; contacts disabled, energy enabled):

* the root link at the world origin, rotated by Rx(+90 deg) so that the machine's world plane
  (x, y up) is MuJoCo's x-z plane (z up): a point (x, y, z) of the description lies at MuJoCo
  (x, -z, y), as in :mod:`hiab_sim.model.mjcf`; below it every position is the description's;
* one body per tree body, placed by its joint frame at zero coordinates, with a ``hinge`` about
  local z or a ``slide`` along local x named after the joint (qpos = the joint coordinate, same
  zero and sign as the description);
* every body's inertia from the description (mass, centre of mass, full 3x3 inertia in its frame);
* per loop pin, sites ``<pin>.a`` / ``<pin>.b`` and a site-based ``connect`` equality ``<pin>``;
  site ``tcp`` is the TCP frame;
* one ``motor`` per chain (named after it, gear 1, no control limit) on its actuated joint (the
  rod slide, or the direct chain's prismatic joint): ctrl is the actuator force f_x [N];
* with ``limits=True`` (the exported file, :mod:`hiab_sim.machine_mjcf`), the ranges of
  :func:`joint_ranges` as ``limited`` joint ranges: each machine hinge's working range [rad] and
  each actuator slide's stroke [0, stroke] [m] (a rod slide's coordinate is x, a direct chain's
  joint is x itself), which ``hiab-sim machine import`` reads back as working ranges and strokes.
  The slides' ranges are the EMLAs' end stops; a hinge's range is the working range the machine
  file declares; the chain bodies' hinges stay unlimited (the loops hold them). A limit acts only
  outside its range (MuJoCo instantiates a limit row once the coordinate passes it) and both ID
  paths disable constraints, so no force inside the ranges changes. The ID paths' and the
  simulation environment's models are built with ``limits=False``.

The bare model (``extras=None``) is the mechanism: inverse dynamics of it gives the load-side
actuator forces. :class:`SimulationExtras` adds, per actuator, the armature [kg] (rotor and screw
inertia reflected to the rod, ``J_m k^2 + M_sm``, eq. ``torque_torque``) and the viscous damping
[N s/m] (screw friction, eq. ``torque_force``) on the actuated joint: inverse dynamics of that model
gives the motor-side forces f_x + (J_m k^2 + M_sm) a_x + b_f v_x.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.tree import MachineTree, SimulationExtras, actuator_lengths, machine_tree
from hiab_sim.machine.parts import RigidBody
from hiab_sim.model.mjcf import SOURCE_TO_WORLD, add_site_connect
from hiab_sim.resources import mjcf_template

__all__ = ["SimulationExtras", "build_machine_model", "build_machine_spec", "joint_ranges", "spec_of_tree"]


def _quat(rotation: np.ndarray) -> list[float]:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(rotation, dtype=float).reshape(9))
    return [float(v) for v in quat]


def _set_inertial(body: mujoco.MjsBody, inertia: RigidBody) -> None:
    full = np.asarray(inertia.inertia, dtype=float)
    body.explicitinertial = True
    body.mass = inertia.mass
    body.ipos = list(inertia.com)
    body.fullinertia = [full[0, 0], full[1, 1], full[2, 2], full[0, 1], full[0, 2], full[1, 2]]


#: Visual capsules (no mass, no contact): radius [m] and template material, per kind of body.
_LOOK = {"link": (0.05, "hiab_red"), "cylinder": (0.045, "cylinder"), "rod": (0.025, "rod")}


def _capsule(body: mujoco.MjsBody, start: Any, end: Any, look: str) -> None:
    if float(np.linalg.norm(np.asarray(end, float) - np.asarray(start, float))) < 1e-6:
        return
    radius, material = _LOOK[look]
    geom = body.add_geom()
    geom.type = mujoco.mjtGeom.mjGEOM_CAPSULE
    geom.size = [radius, 0.0, 0.0]
    geom.material = material
    geom.contype = 0
    geom.conaffinity = 0
    geom.group = 1
    geom.fromto = [*map(float, start), *map(float, end)]


def joint_ranges(tree: MachineTree) -> dict[str, tuple[float, float]]:
    """The ranges the exported MJCF gives its joints, by joint name [rad or m] (see the module docstring).

    Each machine joint driven through a triangle or a linkage: its working range (``joint_range``
    of its link). Each actuator's slide: [0, stroke] (the rod slide's coordinate is the stroke x,
    0 at the retracted length; a direct chain's prismatic joint is x itself, so its range is the
    stroke too, which is what the import reads as that link's working range).
    """
    machine = tree.machine
    out: dict[str, tuple[float, float]] = {}
    for name in machine.joint_names:
        span = machine.joint_link(name).joint_range
        if span is not None:
            out[name] = (float(span[0]), float(span[1]))
    for chain, b in zip(machine.chains, tree.actuated, strict=True):
        out[tree.bodies[b].joint] = (0.0, float(chain.actuator.stroke))
    return out


def build_machine_spec(
    machine: Machine,
    design: Sequence[float] | None = None,
    extras: SimulationExtras | None = None,
    *,
    limits: bool = False,
) -> mujoco.MjSpec:
    """MjSpec of the machine with its decision variables set to ``design`` (default: the file's).

    ``limits``: give the joints the ranges of :func:`joint_ranges` (the exported file's end stops).

    Raises:
        InvalidInputError: a design outside its bounds, a moving body without mass, extras of the
            wrong length (the field is named).

    """
    if design is not None:
        machine = machine.with_design(design)
    return spec_of_tree(machine_tree(machine), extras, limits=limits)


def spec_of_tree(tree: MachineTree, extras: SimulationExtras | None = None, *, limits: bool = False) -> mujoco.MjSpec:
    """MjSpec of a machine tree (see the module docstring); ``limits`` as :func:`build_machine_spec`."""
    machine = tree.machine
    ranges = joint_ranges(tree) if limits else {}
    spec = mujoco.MjSpec.from_string(mjcf_template())
    spec.modelname = machine.name
    spec.option.gravity = [0.0, 0.0, -machine.gravity]
    spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    made: list[mujoco.MjsBody] = []
    for body in tree.bodies:
        if body.parent < 0:
            node = spec.worldbody.add_body(
                name=body.name, pos=list(SOURCE_TO_WORLD @ body.position), quat=_quat(SOURCE_TO_WORLD @ body.rotation)
            )
        else:
            node = made[body.parent].add_body(name=body.name, pos=list(body.position), quat=_quat(body.rotation))
            kind = mujoco.mjtJoint.mjJNT_HINGE if body.kind == "revolute" else mujoco.mjtJoint.mjJNT_SLIDE
            axis = [0.0, 0.0, 1.0] if body.kind == "revolute" else [1.0, 0.0, 0.0]
            hinge_or_slide = node.add_joint(name=body.joint, type=kind, axis=axis)
            if body.joint in ranges:
                hinge_or_slide.range = list(ranges[body.joint])
                hinge_or_slide.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            if body.inertia is None:
                raise InvalidInputError(f"bodies.{body.name}", "no mass", "a moving body needs a mass for MuJoCo", "kg")
        if body.inertia is not None:
            _set_inertial(node, body.inertia)
        made.append(node)
    _add_visuals(spec, tree, made)
    for loop in tree.loops:
        made[loop.body_a].add_site(name=f"{loop.name}.a", pos=list(loop.point_a))
        made[loop.body_b].add_site(name=f"{loop.name}.b", pos=list(loop.point_b))
        add_site_connect(spec, loop.name, f"{loop.name}.a", f"{loop.name}.b")
    site = made[tree.tcp_body].add_site(
        name="tcp", pos=list(tree.tcp.position), quat=_quat(np.asarray(tree.tcp.rotation)), size=[0.04, 0.04, 0.04]
    )
    site.rgba = [1.0, 0.75, 0.0, 1.0]
    if extras is not None and len(extras.armature_kg) != len(tree.actuated):
        raise InvalidInputError(
            "extras.armature_kg",
            f"{len(extras.armature_kg)} values",
            f"need one per actuator: {machine.actuator_names}",
        )
    for k, (name, b) in enumerate(zip(machine.actuator_names, tree.actuated, strict=True)):
        joint = tree.bodies[b].joint
        motor = spec.add_actuator(name=name, target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        motor.gear = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        if extras is not None:
            spec.joint(joint).armature = extras.armature_kg[k]
            spec.joint(joint).damping = [extras.damping_Ns_per_m[k], 0.0, 0.0]  # linear viscous term only
    return spec


def _add_visuals(spec: mujoco.MjSpec, tree: MachineTree, made: list[mujoco.MjsBody]) -> None:
    """Capsules (no mass, no contact): each link to its children's joints and pivots, cylinders and rods."""
    for b, body in enumerate(tree.bodies):
        if body.chain is not None:
            continue
        for child in tree.bodies:
            if child.parent == b:
                _capsule(made[b], np.zeros(3), child.position, "link")
                link = tree.machine.link(child.name) if child.chain is None else None
                if link is not None and link.joint_kind == "prismatic" and link.joint_range is not None:
                    end = child.position + child.rotation[:, 0] * link.joint_range[1]  # the slide's guide
                    _capsule(made[b], child.position, end, "cylinder")
        for loop in tree.loops:
            if loop.body_b == b:
                _capsule(made[b], np.zeros(3), loop.point_b, "link")
        if b == tree.tcp_body:
            _capsule(made[b], np.zeros(3), tree.tcp.position, "link")
    for chain in tree.machine.chains:
        if chain.kind == "direct":
            continue
        cylinder = tree.index(f"{chain.name}.cylinder")
        piston, rod_length = actuator_lengths(chain)
        _capsule(made[cylinder], np.zeros(3), [piston + rod_length, 0.0, 0.0], "cylinder")
        _capsule(made[cylinder + 1], np.zeros(3), [rod_length, 0.0, 0.0], "rod")
        if chain.kind == "linkage" and chain.linkage is not None:
            _capsule(made[cylinder + 2], np.zeros(3), [chain.linkage.rocker_length, 0.0, 0.0], "link")
            _capsule(made[cylinder + 3], np.zeros(3), [chain.linkage.coupler_length, 0.0, 0.0], "link")


def build_machine_model(
    machine: Machine, design: Sequence[float] | None = None, extras: SimulationExtras | None = None
) -> mujoco.MjModel:
    """Compiled :class:`mujoco.MjModel` of :func:`build_machine_spec`."""
    return build_machine_spec(machine, design, extras).compile()

"""A machine file's MJCF for one design: the design from the command line or a result, posed and framed.

The model is the generic one of :mod:`hiab_sim.machine.dynamics.mjcf_build` (every tree body, the
closed loops as ``connect`` equalities, one force motor per actuator), its joints limited to the
machine's working ranges and the actuator slides to their strokes (``limits=True``: what
``hiab-sim machine import`` reads back). Here it gets what a viewer and a renderer need:

* a keyframe ``home`` at the middle of every joint's working range (within what the design's
  chains reach), every dependent joint (cylinders, rods, rockers, couplers) set by the loop closure
  so that every connect equality holds (|C| < 1e-13 m, :class:`MujocoMachineDynamics.state`);
* the template's floor lowered to :data:`FLOOR_CLEARANCE` below the lowest point the machine reaches
  there, when it reaches under it (the template's floor suits the XS 031 on its truck bed);
* the template's cameras ``side`` and ``perspective`` fitted to the visible geoms at every
  combination of :data:`CAMERA_POSES_PER_JOINT` poses per joint over those ranges.

Joint coordinates in rad (hinges) and m (slides), lengths in m.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from xml.etree import ElementTree

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import MachineDesign
from hiab_sim.machine.dynamics.mujoco_path import MujocoMachineDynamics
from hiab_sim.machine.kinematics.assembly import reachable_joint_range

#: Poses per joint over its working range that the cameras are fitted to (every combination), as the crane's.
CAMERA_POSES_PER_JOINT = 4
#: Aspect ratio (width / height) the cameras are fitted for: the template's off-screen buffer, 1280 x 720.
CAMERA_ASPECT = 16.0 / 9.0
#: Distance kept from a reachable-range end [rad or m]: at the end a chain is at its stroke limit or toggle.
RANGE_INSET = 1e-9


def parse_design(machine: Machine, items: Sequence[str]) -> Array:
    """The machine's design with ``chain.var=value`` items set [m], the file's values elsewhere.

    Raises:
        InvalidInputError: an item without ``=``, an unknown key (the message names the machine's
            keys), a value that is not a finite number, or a key given twice.

    """
    values = np.array(machine.design_values(), dtype=float)
    keys = machine.variable_keys
    seen: set[str] = set()
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep:
            raise InvalidInputError("--design", item, "must be chain.var=value")
        if key not in keys:
            allowed = ", ".join(keys) if keys else "none (the machine declares no decision variables)"
            raise InvalidInputError("--design", key, f"must be one of the machine's variables: {allowed}")
        if key in seen:
            raise InvalidInputError("--design", key, "is given twice")
        seen.add(key)
        try:
            value = float(text)
        except ValueError:
            raise InvalidInputError(f"--design {key}", text, "must be a number", "m") from None
        if not np.isfinite(value):
            raise InvalidInputError(f"--design {key}", text, "must be finite", "m")
        values[keys.index(key)] = value
    return values


def result_design(machine: Machine, design: MachineDesign, where: str) -> Array:
    """A result's design as values in the machine's variable order [m].

    Raises:
        InvalidInputError: the result names other variables than the machine declares.

    """
    if list(design.names) != machine.variable_keys:
        raise InvalidInputError(
            where, ", ".join(design.names), f"must name the machine's variables {machine.variable_keys}"
        )
    return design.as_array()


def working_ranges(machine: Machine) -> list[tuple[float, float]]:
    """Each joint's working range (``machine.joint_names`` order) within what its chain reaches [rad or m]."""
    ranges = []
    for name in machine.joint_names:
        low, high = machine.joint_link(name).joint_range or (0.0, 0.0)
        for chain in machine.chains:
            if chain.joint == name:
                reach = reachable_joint_range(machine, chain)
                if reach is None:
                    raise InvalidInputError(f"chains.{chain.name}", "this design", "the chain does not assemble")
                low, high = max(low, reach[0] + RANGE_INSET), min(high, reach[1] - RANGE_INSET)
        ranges.append((low, high))
    return ranges


def home_joints(machine: Machine) -> Array:
    """The independent joints at the middle of their working ranges, (n_joints,) [rad or m]."""
    return np.array([0.5 * (low + high) for low, high in working_ranges(machine)])


def posed_qpos(dynamics: MujocoMachineDynamics, q: Array) -> Array:
    """Loop-consistent MuJoCo qpos (T, nq) for joint samples q (T, n_joints): every connect equality holds."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    zeros = np.zeros_like(q)
    qpos, _, _ = dynamics.state(q, zeros, zeros)
    return qpos


def workspace_joints(machine: Machine) -> Array:
    """Joint samples (P, n_joints) at every combination of poses over each joint's working range."""
    axes = [np.linspace(low, high, CAMERA_POSES_PER_JOINT) for low, high in working_ranges(machine)]
    return np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, len(axes))


def framing_points(model: mujoco.MjModel, qpos: Array) -> Array:
    """World corners (P, 3) of the visible geoms' bounding boxes at every qpos row [m]."""
    from hiab_sim.render.camera import geom_corners

    data = mujoco.MjData(model)
    corners = []
    for row in np.atleast_2d(qpos):
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        corners.append(geom_corners(model, data))
    return np.concatenate(corners)


def machine_mjcf(machine: Machine, design: Sequence[float] | Array | None = None) -> str:
    """The MJCF text of the machine at ``design`` with keyframe ``home`` and framed cameras (module docstring).

    ``design`` is checked against the declared bounds; pass a machine already set to a design
    (``with_design(..., check_bounds=False)``) and no ``design`` for one the bounds need not hold.
    """
    if design is not None:
        machine = machine.with_design(design)
    dynamics = MujocoMachineDynamics(machine)
    home = posed_qpos(dynamics, home_joints(machine)[None])[0]
    points = framing_points(dynamics.model, posed_qpos(dynamics, workspace_joints(machine)))
    root = ElementTree.fromstring(_bare_xml(machine))
    keyframe = root.find("keyframe")
    if keyframe is None:
        keyframe = ElementTree.SubElement(root, "keyframe")
    # full precision (repr), so that the connect equalities hold at the keyframe to round-off
    ElementTree.SubElement(keyframe, "key", name="home", qpos=" ".join(repr(float(v)) for v in home))
    world = root.find("worldbody")
    if world is None:
        raise AssertionError("an MJCF without a worldbody")
    _lower_floor(world, float(points[:, 2].min()))
    place_cameras(world, points)
    return ElementTree.tostring(root, encoding="unicode")


def place_cameras(world: ElementTree.Element, points: Array) -> None:
    """Set the cameras of an MJCF ``worldbody`` (adding any missing) to frame ``points`` (P, 3) [m].

    Each camera is :func:`hiab_sim.render.camera.framed_cameras`'s at :data:`CAMERA_ASPECT` and the
    first camera's ``fovy`` [deg] (45 without one), given by ``pos`` and ``xyaxes`` (``quat`` and
    ``euler`` dropped); the crane's MJCF (``hiab-sim mjcf``) and a machine file's are framed alike.
    """
    from hiab_sim.render.camera import MODEL_CAMERAS, framed_cameras

    cameras = {c.get("name"): c for c in world.findall("camera")}
    fovy = float(next(iter(cameras.values())).get("fovy", "45")) if cameras else 45.0
    for name, (position, xyaxes) in framed_cameras(points, CAMERA_ASPECT, fovy).items():
        camera = cameras.get(name)
        if camera is None:
            camera = ElementTree.SubElement(world, "camera", name=name, fovy=f"{fovy:g}")
        camera.set("pos", " ".join(f"{v:.4f}" for v in position))
        camera.set("xyaxes", " ".join(f"{v:.4f}" for v in xyaxes))
        camera.attrib.pop("quat", None)
        camera.attrib.pop("euler", None)
    if not set(MODEL_CAMERAS) <= {c.get("name") for c in world.findall("camera")}:
        raise AssertionError("the model lacks a framed camera")


#: Clearance kept between the floor and the lowest point the machine reaches [m] (visual: contacts are off).
FLOOR_CLEARANCE = 0.05


def _lower_floor(world: ElementTree.Element, lowest: float) -> None:
    """Move the template's floor (set for the XS 031's truck bed) below a machine that reaches under it."""
    for geom in world.findall("geom"):
        if geom.get("type") == "plane" and geom.get("pos"):
            position = [float(v) for v in str(geom.get("pos")).split()]
            if position[2] > lowest - FLOOR_CLEARANCE:
                position[2] = lowest - FLOOR_CLEARANCE
                geom.set("pos", _numbers(position))


def _numbers(values: object) -> str:
    return " ".join(repr(float(v)) for v in np.asarray(values, dtype=float).reshape(-1))


def _bare_xml(machine: Machine) -> str:
    """The generic model's XML with its bodies, inertias and sites at full precision.

    ``MjSpec.to_xml`` writes six significant digits (the XS 031's pins then miss by ~4e-6 m), so
    the numbers that place the mechanism are written again from the spec with ``repr``. The joints
    carry their ranges (working ranges and strokes, :func:`~hiab_sim.machine.dynamics.mjcf_build.joint_ranges`)
    so that ``hiab-sim machine import`` reads the file back as it is written.
    """
    from hiab_sim.machine.dynamics.mjcf_build import build_machine_spec

    spec = build_machine_spec(machine, limits=True)
    spec.compile()
    root = ElementTree.fromstring(spec.to_xml())
    for body in root.iter("body"):
        if body.get("name") is None:
            continue
        source = spec.body(str(body.get("name")))
        body.set("pos", _numbers(source.pos))
        body.set("quat", _numbers(source.quat))
        inertial = body.find("inertial")
        if inertial is not None:
            for key in ("quat", "diaginertia", "fullinertia"):
                inertial.attrib.pop(key, None)
            inertial.set("pos", _numbers(source.ipos))
            inertial.set("mass", repr(float(source.mass)))
            inertial.set("fullinertia", _numbers(source.fullinertia))
    for joint in root.iter("joint"):
        if joint.get("range") is not None:
            joint.set("range", _numbers(spec.joint(str(joint.get("name"))).range))
    for site in root.iter("site"):
        if site.get("name") is None:  # the template's decor
            continue
        source = spec.site(str(site.get("name")))
        site.set("pos", _numbers(source.pos))
        site.set("quat", _numbers(source.quat))
    return ElementTree.tostring(root, encoding="unicode")

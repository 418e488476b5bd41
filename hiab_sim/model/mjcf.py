"""MJCF model of the crane for one link-length set Xi, built with :class:`mujoco.MjSpec`.

The shared pieces (materials, visual defaults, lights, cameras, floor, options) are the template
``assets/mjcf/crane_template.xml`` (read through :func:`hiab_sim.resources.mjcf_template`);
:func:`build_spec` loads it and adds the crane.

Frames. hiab-sim keeps the crane in the source frames (world {W} with y up, every revolute
axis along z). The root body ``base`` sits at the world origin with ``quat = Rx(+90 deg)``,
so a source point (x, y, z) lies at MuJoCo world (x, -z, y): z is up and the crane moves in
the world x-z plane. Below ``base`` every position is a source coordinate and every hinge
axis is local z, so the model reads like the data sheet.

Bodies (one per link of :mod:`hiab_sim.crane.description`) and joints:

================  ==================================================  ==========================
body              placement in its parent                             joint (qpos)
================  ==================================================  ==========================
``base``          world origin, Rx(+90 deg)                           none (fixed)
``lift_boom``     boom hinge, Rz(base_axis_angle - joint_offset)      hinge ``theta1`` = Θ1 [rad]
``lift_cylinder`` cylinder base pivot {Bc}, Rz(base_axis_angle)       hinge ``lift_q1`` = q1 < 0
``lift_rod``      (Lc0, 0, 0) in the cylinder                         slide ``x1`` = stroke [m]
``tilt_boom``     on ``lift_boom``, as for the lift chain             hinge ``theta2`` = Θ2 [rad]
``tilt_cylinder`` on ``lift_boom``, as for the lift chain             hinge ``tilt_q1``
``tilt_rod``      (Lc0, 0, 0) in the cylinder                         slide ``x2``
``telescope_rod`` {P22} (rod_offset, 0, 0), axes of {P22}             slide ``xt2`` [m]
================  ==================================================  ==========================

Because the boom body is rotated by Rz(base_axis_angle - joint_offset) and the hinge turns it
by qpos about z, the boom's rotation relative to {Bc} is qpos - joint_offset, which is the
source's convention: qpos of ``theta1``/``theta2`` equals Θ1/Θ2 exactly (same zero, same sign).
The cylinder's hinge angle is the seed's q1 (eq. qus), the angle of the cylinder axis from
{Bc}'s x axis; the slide is 0 at the retracted pin-to-pin length x0 = Lc + Lc0.

Closed chains (seed const_m): site ``<chain>_base_pivot`` marks {Bc} on the cylinder. Site
``<chain>_rod_end`` at (Lc, 0, 0) on the rod and site ``<chain>_boom_pivot`` at (L1, 0, 0) on
the boom are joined by a site-based ``connect`` equality named ``<chain>_loop``. Site ``tcp``
is the TCP frame {D22} on the telescope rod; site ``telescope_cylinder`` is {P22}.

Motors ``lift``, ``tilt``, ``telescope`` (gear 1, no control limits) act on ``x1``, ``x2``,
``xt2`` for forward replay; ctrl is the actuator force f_x [N], positive extending.

Inertia. Every :class:`~hiab_sim.crane.description.RigidBody` of ``crane.bodies_for(lengths)`` is merged
into the body of its link (several bodies on one link: ``lift_boom_a`` + ``lift_boom_b``,
``tilt_boom`` + ``telescope_cylinder``, ``telescope_rod`` + ``end_mass``): total mass, common
centre of mass, and inertia about it by the parallel-axis theorem. This is exact for rigidly
joined bodies and keeps the tree at one body per moving link.

Link lengths. Xi changes nothing but the closed chains' cylinder base pivots and their
cylinder and rod bodies: the pivot moves along its fixed direction from the boom hinge
(``ClosedChain.base_pivot``), the rod-end site moves to (Lc, 0, 0), the rod body to
(Lc0, 0, 0), and masses and inertias of cylinder and rod scale by the slender-body rule of
:meth:`hiab_sim.crane.description.Crane.bodies_for` (mass and com with length, axial inertia with l,
transverse with l^3; the cylinder's length is x0, the rod's Lc). Hinges, booms and TCP stay.

Contacts are disabled (the loop bodies overlap by design); geoms are visual only.
"""

from __future__ import annotations

import math
from xml.etree import ElementTree

import mujoco
import numpy as np

from hiab_sim.crane import mechanism, names
from hiab_sim.crane.description import ClosedChain, Crane, LinkLengths, RigidBody
from hiab_sim.crane.mechanism import check_lengths
from hiab_sim.errors import ConfigError
from hiab_sim.model.drives import HomePose, SlideDrives
from hiab_sim.resources import mjcf_template

#: Independent joints (qpos equals the source's Θ1, Θ2, xt2) and the actuated slides, in order.
JOINTS = names.JOINT_NAMES
SLIDES = ("x1", "x2", names.XT2)
ACTUATORS = names.ACTUATOR_NAMES
#: Passive joints of the closed chains: cylinder hinge (seed's q1) and stroke, per chain.
PASSIVE = ("lift_q1", "x1", "tilt_q1", "x2")
_CHAIN_JOINT = {names.LIFT: (names.THETA1, "x1"), names.TILT: (names.THETA2, "x2")}

#: Default equality ``solref`` (timeconst [s], damping ratio) and ``solimp``: see replay.py.
EQUALITY_SOLREF = (0.002, 1.0)
EQUALITY_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)

#: Source frame {W} (y up) -> MuJoCo world (z up): Rx(+90 deg), (x, y, z) -> (x, -z, y).
SOURCE_TO_WORLD_QUAT = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)
SOURCE_TO_WORLD = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def source_to_world(points: np.ndarray) -> np.ndarray:
    """Map source-frame points or vectors (..., 3) to MuJoCo world coordinates: (x, -z, y)."""
    return np.asarray(points, dtype=float) @ SOURCE_TO_WORLD.T


def _quat_z(angle: float) -> list[float]:
    return [math.cos(angle / 2.0), 0.0, 0.0, math.sin(angle / 2.0)]


def _quat(rotation: np.ndarray) -> list[float]:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(rotation, dtype=float).reshape(9))
    return [float(v) for v in quat]


def merge_bodies(bodies: list[RigidBody]) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass [kg], com [m] and inertia about the com [kg m^2] of rigidly joined bodies (parallel axes)."""
    masses = np.array([b.mass for b in bodies])
    coms = np.array([b.com for b in bodies])
    mass = float(masses.sum())
    com = masses @ coms / mass
    offsets = coms - com
    inertia = np.sum([np.asarray(b.inertia) for b in bodies], axis=0)
    inertia = inertia + np.einsum("i,ij,ik->jk", masses, offsets, offsets) * -1.0
    inertia = inertia + np.eye(3) * float(np.einsum("i,ij,ij->", masses, offsets, offsets))
    return mass, com, inertia


def _set_inertial(body: mujoco.MjsBody, bodies: list[RigidBody]) -> None:
    mass, com, inertia = merge_bodies(bodies)
    body.explicitinertial = True
    body.mass = mass
    body.ipos = com
    body.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]


def _capsule(body: mujoco.MjsBody, start: np.ndarray, end: np.ndarray, cls: mujoco.MjsDefault) -> None:
    if float(np.linalg.norm(np.asarray(end) - np.asarray(start))) < 1e-6:
        return
    geom = body.add_geom(default=cls)
    geom.type = mujoco.mjtGeom.mjGEOM_CAPSULE
    geom.fromto = [*map(float, start), *map(float, end)]


def _add_chain(
    spec: mujoco.MjSpec,
    parent: mujoco.MjsBody,
    chain: ClosedChain,
    lengths: LinkLengths,
    links: dict[str, list],
    ref: dict[str, float],
) -> mujoco.MjsBody:
    """Add boom, cylinder and rod of one closed chain under ``parent``; return the boom body.

    ``ref`` maps joint names to the value at which the bodies are placed (joint ``ref``, qpos0).
    """
    xi = getattr(lengths, chain.name)
    hinge_name, slide_name = _CHAIN_JOINT[chain.name]
    theta = ref.get(hinge_name, 0.0)
    boom = parent.add_body(
        name=names.boom_link(chain.name),
        pos=chain.boom_hinge,
        quat=_quat_z(chain.base_axis_angle - chain.joint_offset + theta),
    )
    boom.add_joint(name=hinge_name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0], ref=theta)
    boom.add_site(name=f"{chain.name}_boom_pivot", pos=[chain.L1, 0.0, 0.0])
    _set_inertial(boom, links[names.boom_link(chain.name)])
    _capsule(boom, np.zeros(3), np.array([chain.L1, 0.0, 0.0]), spec.find_default("boom"))

    q1 = ref.get(f"{chain.name}_q1", 0.0)
    cylinder = parent.add_body(
        name=names.cylinder_link(chain.name), pos=chain.base_pivot(xi), quat=_quat_z(chain.base_axis_angle + q1)
    )
    cylinder.add_joint(name=f"{chain.name}_q1", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0], ref=q1)
    cylinder.add_site(name=f"{chain.name}_base_pivot")
    _set_inertial(cylinder, links[names.cylinder_link(chain.name)])
    _capsule(cylinder, np.zeros(3), np.array([xi.x0, 0.0, 0.0]), spec.find_default("barrel"))

    stroke = ref.get(slide_name, 0.0)
    rod = cylinder.add_body(name=names.rod_link(chain.name), pos=[xi.Lc0 + stroke, 0.0, 0.0])
    rod.add_joint(name=slide_name, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1.0, 0.0, 0.0], ref=stroke)
    rod.add_site(name=f"{chain.name}_rod_end", pos=[xi.Lc, 0.0, 0.0])
    _set_inertial(rod, links[names.rod_link(chain.name)])
    _capsule(rod, np.zeros(3), np.array([xi.Lc, 0.0, 0.0]), spec.find_default("rod"))

    add_site_connect(spec, f"{chain.name}_loop", f"{chain.name}_rod_end", f"{chain.name}_boom_pivot")
    return boom


def build_spec(
    crane: Crane,
    lengths: LinkLengths | None = None,
    drives: SlideDrives | None = None,
    home: HomePose | None = None,
) -> mujoco.MjSpec:
    """MjSpec of the crane for link lengths Xi (default: the crane's own), see the module docstring.

    Without ``drives`` this is the inverse-dynamics model (no armature, damping, ranges or force
    limits: its slide force is the load-side f_x). With ``drives`` it is the simulation model of
    :mod:`hiab_sim.model.drives`; ``home`` places the bodies at that pose (joint ``ref``, so qpos0 is
    the home pose and ``mj_resetData`` and the viewer open there) and, with servo gains, makes the
    actuators stroke servos that hold it at ``ctrl`` = 0.

    Raises:
        InvalidInputError: the lengths are infeasible for the crane's working joint ranges
            (:func:`hiab_sim.crane.mechanism.check_lengths`, const_g .. const_k); the field is named.

    """
    lengths = crane.default_lengths if lengths is None else lengths
    check_lengths(crane, lengths)
    ref = dict(home.qpos) if home is not None else {}
    links: dict[str, list[RigidBody]] = {}
    for body in crane.bodies_for(lengths):
        links.setdefault(body.link, []).append(body)

    spec = mujoco.MjSpec.from_string(mjcf_template())
    spec.modelname = crane.name
    spec.option.gravity = [0.0, 0.0, -crane.gravity]
    base = spec.worldbody.add_body(name=names.BASE, quat=list(SOURCE_TO_WORLD_QUAT))
    if names.BASE in links:
        _set_inertial(base, links[names.BASE])
    bodies = {names.BASE: base}
    for point in (
        *(c.base_pivot(getattr(lengths, c.name)) for c in crane.chains if c.parent == names.BASE),
        *(c.boom_hinge for c in crane.chains if c.parent == names.BASE),
    ):
        _capsule(base, np.array([point[0], 0.0, 0.0]), point, spec.find_default("boom"))
    _capsule(base, np.array([0.0, -0.6, 0.0]), np.zeros(3), spec.find_default("boom"))

    pending = list(crane.chains)
    while pending:  # parents first: a chain may sit on another chain's boom
        chain = next((c for c in pending if c.parent in bodies), None)
        if chain is None:
            raise ConfigError(f"chain parent(s) {[c.parent for c in pending]} are not links of the crane")
        pending.remove(chain)
        bodies[names.boom_link(chain.name)] = _add_chain(spec, bodies[chain.parent], chain, lengths, links, ref)
        parent = bodies[chain.parent]
        if chain.parent != names.BASE:
            _capsule(parent, np.zeros(3), chain.boom_hinge, spec.find_default("boom"))
            _capsule(
                parent, chain.boom_hinge, chain.base_pivot(getattr(lengths, chain.name)), spec.find_default("boom")
            )

    tele = crane.telescope
    if tele.parent not in bodies:
        raise ConfigError(f"telescope.parent '{tele.parent}' is not a boom of the crane")
    carrier = bodies[tele.parent]
    frame = tele.cylinder_frame
    rotation = np.asarray(frame.rotation)
    origin = np.asarray(frame.position)
    carrier.add_site(name=names.TELESCOPE_CYLINDER, pos=origin, quat=_quat(rotation))
    _capsule(carrier, np.zeros(3), origin, spec.find_default("boom"))
    barrel_end = origin + rotation[:, 0] * (tele.rod_offset + tele.stroke)
    _capsule(carrier, origin, barrel_end, spec.find_default("boom"))
    xt2 = ref.get(names.XT2, 0.0)
    rod = carrier.add_body(
        name=names.TELESCOPE_ROD, pos=origin + rotation[:, 0] * (tele.rod_offset + xt2), quat=_quat(rotation)
    )
    rod.add_joint(name=names.XT2, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1.0, 0.0, 0.0], ref=xt2)
    _set_inertial(rod, links[names.TELESCOPE_ROD])
    _capsule(rod, np.zeros(3), np.array([tele.rod_length, 0.0, 0.0]), spec.find_default("barrel"))
    tcp = crane.tcp_in_telescope_rod
    _capsule(rod, np.array([tele.rod_length, 0.0, 0.0]), np.asarray(tcp.position), spec.find_default("barrel"))
    site = rod.add_site(name="tcp", pos=tcp.position, quat=_quat(np.asarray(tcp.rotation)), size=[0.04, 0.04, 0.04])
    site.rgba = [1.0, 0.75, 0.0, 1.0]

    for name, joint in zip(ACTUATORS, SLIDES, strict=True):
        motor = spec.add_actuator(name=name, target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        motor.gear = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
    if drives is not None:
        _add_drives(spec, crane, lengths, drives, home)
    return spec


def _add_drives(
    spec: mujoco.MjSpec, crane: Crane, lengths: LinkLengths, drives: SlideDrives, home: HomePose | None
) -> None:
    """Armature, damping, stops and EMLA force limits of the simulation model (:mod:`hiab_sim.model.drives`)."""
    stops: dict[str, tuple[float, float]] = {names.XT2: (0.0, crane.telescope.stroke)}
    for chain in crane.chains:
        xi = getattr(lengths, chain.name)
        hinge, slide = _CHAIN_JOINT[chain.name]
        stops[slide] = (0.0, min(chain.stroke, xi.Lc))
        stops[hinge] = mechanism.reachable_joint_range(chain, xi)
    for name, (low, high) in stops.items():
        joint = spec.joint(name)
        joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        joint.range = [low, high]
    for index, (name, slide) in enumerate(zip(ACTUATORS, SLIDES, strict=True)):
        joint = spec.joint(slide)
        joint.armature = drives.armature[index]
        joint.damping = [drives.damping[index], 0.0, 0.0]  # linear viscous term only
        limit = drives.force_limit[index]
        actuator = spec.actuator(name)
        actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.forcerange = [-limit, limit]
        actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.ctrlrange = [-limit, limit]
        if home is not None and home.servo is not None:
            kp, kv = home.servo[0][index], home.servo[1][index]
            x_home = home.qpos[slide]
            low, high = stops[slide]
            actuator.gaintype = mujoco.mjtGain.mjGAIN_FIXED
            actuator.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            actuator.gainprm[0] = kp
            actuator.biasprm[:3] = [home.force[index] + kp * x_home, -kp, -kv]
            actuator.ctrlrange = [low - x_home, high - x_home]


def build_model(
    crane: Crane,
    lengths: LinkLengths | None = None,
    drives: SlideDrives | None = None,
    home: HomePose | None = None,
) -> mujoco.MjModel:
    """Compiled :class:`mujoco.MjModel` of the crane for link lengths Xi (see :func:`build_spec`)."""
    return build_spec(crane, lengths, drives, home).compile()


def to_xml(
    crane: Crane,
    lengths: LinkLengths | None = None,
    keyframes: dict[str, tuple[np.ndarray, np.ndarray]] | None = None,
    drives: SlideDrives | None = None,
    home: HomePose | None = None,
) -> str:
    """MJCF text of the crane for link lengths Xi; loads with ``mujoco.MjModel.from_xml_string``.

    MuJoCo's XML writer keeps 6 significant digits, which would open the closed loops by ~1e-6 m
    and round masses; every body, inertial, geom and site placement is therefore rewritten
    from the compiled model at full double precision (``repr``), so the file reloads to the
    same model to round-off.

    Args:
        crane: The crane.
        lengths: Link lengths Xi (default: the crane's own).
        keyframes: Optional named keyframes, name -> (qpos (nq,), ctrl (nu,)), written at full
            precision (e.g. a loop-consistent ``home`` pose with its gravity-holding forces).
        drives: Optional EMLA drives (simulation model, see :func:`build_spec`).
        home: Optional pose the model opens in (see :func:`build_spec`).

    """
    spec = build_spec(crane, lengths, drives, home)
    model = spec.compile()
    root = ElementTree.fromstring(spec.to_xml())
    if keyframes:
        frames = ElementTree.SubElement(root, "keyframe")
        for name, (qpos, ctrl) in keyframes.items():
            key = ElementTree.SubElement(frames, "key", name=name)
            _set(key, qpos=np.asarray(qpos).reshape(model.nq), ctrl=np.asarray(ctrl).reshape(model.nu))
    world = root.find("worldbody")
    if world is None:
        raise AssertionError("MuJoCo wrote no worldbody")
    for body_id, body in enumerate(world.iter("body"), start=1):  # depth-first, as MuJoCo numbers them
        _set(body, pos=model.body_pos[body_id], quat=model.body_quat[body_id])
        inertial = body.find("inertial")
        if inertial is not None:
            _set(
                inertial,
                pos=model.body_ipos[body_id],
                quat=model.body_iquat[body_id],
                mass=[model.body_mass[body_id]],
                diaginertia=model.body_inertia[body_id],
            )
    for geom_id, geom in enumerate(world.iter("geom")):
        _set(geom, pos=model.geom_pos[geom_id], quat=model.geom_quat[geom_id])
        if geom.get("type", "") != "plane":
            geom.set("size", _text(model.geom_size[geom_id][: len(geom.get("size", "0 0").split())]))
    for joint in world.iter("joint"):  # joint ref = qpos0 of a hinge or slide (the home pose)
        if joint.get("ref") is not None:
            joint.set("ref", repr(float(model.qpos0[model.joint(joint.get("name", "")).qposadr[0]])))
    for site in world.iter("site"):
        site_id = model.site(site.get("name", "")).id
        _set(site, pos=model.site_pos[site_id], quat=model.site_quat[site_id])
    return ElementTree.tostring(root, encoding="unicode")


def _text(values: np.ndarray) -> str:
    return " ".join(repr(float(v)) for v in values)


def _set(element: ElementTree.Element, **attributes: np.ndarray | list[float]) -> None:
    for key, values in attributes.items():
        element.set(key, _text(np.asarray(values)))


def add_site_connect(spec: mujoco.MjSpec, name: str, site_a: str, site_b: str) -> None:
    """Close a loop: a connect equality ``name`` pinning site ``site_a`` to ``site_b`` (EQUALITY_SOLREF/SOLIMP)."""
    spec.add_equality(
        name=name,
        type=mujoco.mjtEq.mjEQ_CONNECT,
        objtype=mujoco.mjtObj.mjOBJ_SITE,
        name1=site_a,
        name2=site_b,
        solref=list(EQUALITY_SOLREF),
        solimp=list(EQUALITY_SOLIMP),
    )

"""An MJCF model read as a planar mechanism: rigid groups of bodies, pins and slides, closed chains.

MuJoCo compiles the file (:func:`mujoco.MjModel.from_xml_path`), so default classes, ``childclass``,
every orientation form, ``fullinertia``/``diaginertia``, ``inertiafromgeom``, ``ref`` and
``springref`` are as MuJoCo has them. Here:

* bodies with no joint (or only joints locked with ``--lock``) are welded to their parent: a
  **group** is one rigid part of the mechanism (group 0 holds the world);
* every hinge and slide joint is an edge from its body's parent group to its body's group, every
  active ``connect`` equality an edge (a pin) between its two bodies' groups; the joints form a
  spanning tree of the groups and each ``connect`` closes one fundamental loop;
* the **plane** of motion is normal to the hinge axes (``auto``: the axis most hinges share), or
  the named plane; gravity's in-plane part is the machine's gravity, its direction "down";
* a **closed chain** is a union of fundamental loops sharing an edge; it must hold exactly one
  slide (the actuator): a triangle (4 groups, 4 edges) or a four-bar linkage (6 groups, 7 edges);
* a slide joint outside every loop is a prismatic joint driven directly by its actuator.

What the machine format cannot represent is one line each naming the MJCF element
(:class:`UnsupportedMJCFError`). Positions in m, in MuJoCo's world frame unless said otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.errors import HiabSimError

#: Parallelism tolerance of joint axes with the plane normal (|sin| of the angle).
AXIS_TOLERANCE = 1e-6
_HINGE, _SLIDE = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
_BALL, _FREE = int(mujoco.mjtJoint.mjJNT_BALL), int(mujoco.mjtJoint.mjJNT_FREE)
PLANES = {"xz": 1, "xy": 2, "yz": 0}  # plane -> index of the world axis that is its normal


class UnsupportedMJCFError(HiabSimError):
    """The MJCF holds constructs the machine format cannot represent; one line per construct."""

    def __init__(self, lines: list[str]) -> None:
        super().__init__("\n".join(lines))
        self.lines = lines


def name_of(model: mujoco.MjModel, kind: mujoco.mjtObj, index: int, fallback: str) -> str:
    """The element's MJCF name, or ``<fallback><index>`` when it has none."""
    name = mujoco.mj_id2name(model, kind, index)
    return name if name else f"{fallback}{index}"


@dataclass(frozen=True)
class Edge:
    """A joint or a ``connect`` between groups ``a`` (the joint's parent side) and ``b``.

    ``kind``: ``hinge``, ``slide`` or ``pin`` (a connect); ``index``: joint id or equality id;
    ``element``: how the MJCF names it (``joint 'x'``, ``equality 'y'``).
    """

    kind: str
    a: int
    b: int
    index: int
    element: str


@dataclass(frozen=True)
class ClosedChain:
    """A loop block: its edges (indices into :attr:`Mechanism.edges`), groups and the one slide."""

    edges: tuple[int, ...]
    groups: tuple[int, ...]
    slide: int


@dataclass
class Mechanism:
    """The MJCF's groups, edges, plane and closed chains (see the module docstring)."""

    model: mujoco.MjModel
    group_of_body: list[int]
    edges: list[Edge]
    normal: Array
    down: Array
    gravity: float
    locked: dict[int, float]
    chains: list[ClosedChain] = field(default_factory=list)

    @property
    def n_groups(self) -> int:
        """Number of rigid groups (the world's included)."""
        return max(self.group_of_body) + 1

    def bodies(self, group: int) -> list[int]:
        """MuJoCo body ids of a group."""
        return [b for b, g in enumerate(self.group_of_body) if g == group]

    def incident(self, group: int) -> list[int]:
        """Edges touching a group."""
        return [k for k, e in enumerate(self.edges) if group in (e.a, e.b)]


def _locks(model: mujoco.MjModel, locks: dict[str, float]) -> dict[int, float]:
    out: dict[int, float] = {}
    for name, value in locks.items():
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j < 0:
            raise UnsupportedMJCFError([f"--lock {name}={value:g}: the MJCF has no joint '{name}'"])
        if int(model.jnt_type[j]) not in (_HINGE, _SLIDE):
            raise UnsupportedMJCFError([f"--lock {name}: only hinge and slide joints can be locked"])
        out[j] = float(value)
    return out


def _plane_normal(model: mujoco.MjModel, data: mujoco.MjData, hinges: list[int], plane: str) -> Array:
    """Unit plane normal: the named plane's axis, or the direction most hinge axes share (sign of the first)."""
    axes = [np.asarray(data.xaxis[j], dtype=float) for j in hinges]
    if plane != "auto":
        normal = np.zeros(3)
        normal[PLANES[plane]] = 1.0
        for axis in axes:
            if abs(float(axis @ normal)) > 1.0 - AXIS_TOLERANCE:
                return normal * np.sign(float(axis @ normal))
        return normal
    if not axes:
        raise UnsupportedMJCFError(["model: no hinge joint to find the plane from; name it with --plane xz|xy|yz"])
    best = max(axes, key=lambda a: sum(abs(float(a @ b)) > 1.0 - AXIS_TOLERANCE for b in axes))
    return best / np.linalg.norm(best)


def read_mechanism(model: mujoco.MjModel, locks: dict[str, float], plane: str = "auto") -> Mechanism:
    """Groups, edges, plane and closed chains of a compiled model (see the module docstring).

    Raises:
        UnsupportedMJCFError: one line per construct the machine format cannot represent.

    """
    problems: list[str] = []
    for t in range(model.ntendon):
        problems.append(
            f"tendon '{name_of(model, mujoco.mjtObj.mjOBJ_TENDON, t, 'tendon')}': tendons are not supported"
        )
    for f in range(model.nflex):
        problems.append(f"flex '{name_of(model, mujoco.mjtObj.mjOBJ_FLEX, f, 'flex')}': flexes are not supported")
    locked = _locks(model, locks)
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    for j, value in locked.items():
        data.qpos[model.jnt_qposadr[j]] = value
    mujoco.mj_kinematics(model, data)
    joints_of_body: dict[int, list[int]] = {}
    for j in range(model.njnt):
        jname = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
        if int(model.jnt_type[j]) in (_BALL, _FREE):
            kind = "ball" if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL else "free"
            problems.append(f"joint '{jname}' ({kind}): ball and free joints cannot move in a plane chain")
            continue
        if j not in locked:
            joints_of_body.setdefault(int(model.jnt_bodyid[j]), []).append(j)
    for body, joints in joints_of_body.items():
        if len(joints) > 1:
            bname = name_of(model, mujoco.mjtObj.mjOBJ_BODY, body, "body")
            problems.append(f"body '{bname}': {len(joints)} joints on one body (one hinge or slide per body)")
    hinges = [j for js in joints_of_body.values() for j in js if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    normal = _plane_normal(model, data, hinges, plane)
    gravity_world = np.asarray(model.opt.gravity, dtype=float)
    in_plane = gravity_world - float(gravity_world @ normal) * normal
    if np.linalg.norm(in_plane) <= 1e-9:
        problems.append(f"option gravity {gravity_world.tolist()}: has no component in the plane of motion")
    for js in joints_of_body.values():
        for j in js:
            jname = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
            axis = np.asarray(data.xaxis[j], dtype=float)
            cosine = float(axis @ normal)
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE and abs(cosine) < 1.0 - AXIS_TOLERANCE:
                what = "turns the machine out of its plane (a slewing joint)"
                if abs(cosine) > AXIS_TOLERANCE:
                    what = "is neither the plane normal nor in the plane"
                problems.append(
                    f"joint '{jname}': hinge axis {np.round(axis, 6).tolist()} {what}; "
                    f"plane normal {np.round(normal, 6).tolist()}: lock it with --lock {jname}=VALUE"
                )
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE and abs(cosine) > AXIS_TOLERANCE:
                problems.append(
                    f"joint '{jname}': slide axis {np.round(axis, 6).tolist()} leaves the plane of motion "
                    f"(normal {np.round(normal, 6).tolist()}): lock it with --lock {jname}=VALUE"
                )
    group = [0] * model.nbody
    count = 1
    edges: list[Edge] = []
    for body in range(1, model.nbody):
        js = joints_of_body.get(body, [])
        if not js:
            group[body] = group[int(model.body_parentid[body])]
            continue
        group[body] = count
        count += 1
        j = js[0]
        kind = "hinge" if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE else "slide"
        jname = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
        edges.append(Edge(kind, group[int(model.body_parentid[body])], count - 1, j, f"joint '{jname}'"))
    for e in range(model.neq):
        ename = name_of(model, mujoco.mjtObj.mjOBJ_EQUALITY, e, "equality")
        if not model.eq_active0[e]:
            continue
        if model.eq_type[e] != mujoco.mjtEq.mjEQ_CONNECT:
            kind_name = mujoco.mjtEq(model.eq_type[e]).name.removeprefix("mjEQ_").lower()
            problems.append(f"equality '{ename}' ({kind_name}): only connect equalities can close a loop")
            continue
        b1, b2 = _connect_bodies(model, e)
        edges.append(Edge("pin", group[b1], group[b2], e, f"equality '{ename}'"))
    hinge_names = [e.element.removeprefix("joint ") for e in edges if e.kind == "hinge"]
    if hinge_names and not any(e.kind == "pin" for e in edges):
        problems.append(
            "model: no active connect equality closes a loop, so no cylinder drives the hinges "
            f"{', '.join(hinge_names)} (pin each cylinder's rod end to its link with <connect>)"
        )
    if problems:
        raise UnsupportedMJCFError(problems)
    mech = Mechanism(
        model, group, edges, normal, in_plane / np.linalg.norm(in_plane), float(np.linalg.norm(in_plane)), locked
    )
    mech.chains = _closed_chains(mech)
    return mech


def _connect_bodies(model: mujoco.MjModel, e: int) -> tuple[int, int]:
    """The two body ids of a connect equality (body- or site-based)."""
    a, b = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
    if model.eq_objtype[e] == mujoco.mjtObj.mjOBJ_SITE:
        return int(model.site_bodyid[a]), int(model.site_bodyid[b])
    return a, b


def connect_points(model: mujoco.MjModel, data: mujoco.MjData, e: int) -> tuple[Array, Array]:
    """World positions of a connect's two anchors at the data's kinematics [m]."""
    a, b = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
    if model.eq_objtype[e] == mujoco.mjtObj.mjOBJ_SITE:
        return data.site_xpos[a].copy(), data.site_xpos[b].copy()
    anchor1, anchor2 = model.eq_data[e, 0:3], model.eq_data[e, 3:6]
    p1 = data.xpos[a] + data.xmat[a].reshape(3, 3) @ anchor1
    p2 = data.xpos[b] + data.xmat[b].reshape(3, 3) @ anchor2
    return p1, p2


def _tree_path(mech: Mechanism, a: int, b: int) -> set[int]:
    """Joint edges on the tree path between two groups."""
    parent_edge = {e.b: k for k, e in enumerate(mech.edges) if e.kind != "pin"}

    def up(g: int) -> list[int]:
        out = []
        while g != 0:
            k = parent_edge[g]
            out.append(k)
            g = mech.edges[k].a
        return out

    pa, pb = up(a), up(b)
    return set(pa) ^ set(pb)


def _closed_chains(mech: Mechanism) -> list[ClosedChain]:
    """Loop blocks: fundamental loops of the connects, merged when they share an edge; one slide each."""
    loops = {k: _tree_path(mech, e.a, e.b) | {k} for k, e in enumerate(mech.edges) if e.kind == "pin"}
    blocks: list[set[int]] = []
    for cycle in loops.values():
        merged = [b for b in blocks if b & cycle]
        for b in merged:
            blocks.remove(b)
            cycle = cycle | b
        blocks.append(cycle)
    problems: list[str] = []
    chains: list[ClosedChain] = []
    for block in blocks:
        edges = sorted(block)
        slides = [k for k in edges if mech.edges[k].kind == "slide"]
        connects = ", ".join(mech.edges[k].element for k in edges if mech.edges[k].kind == "pin")
        groups = sorted({g for k in edges for g in (mech.edges[k].a, mech.edges[k].b)})
        if not slides:
            problems.append(f"{connects}: closes a loop with no slide joint (no actuator drives it)")
        elif len(slides) > 1:
            names = ", ".join(mech.edges[k].element for k in slides)
            problems.append(f"{names}: two actuators (slide joints) in one closed loop ({connects})")
        elif (len(groups), len(edges)) not in ((4, 4), (6, 7)):
            problems.append(
                f"{connects}: a closed chain of {len(groups)} bodies and {len(edges)} joints is neither a "
                "triangle (4, 4) nor a four-bar linkage (6, 7)"
            )
        else:
            chains.append(ClosedChain(tuple(edges), tuple(groups), slides[0]))
    if problems:
        raise UnsupportedMJCFError(problems)
    return chains


def actuator_on(model: mujoco.MjModel, joint: int) -> str | None:
    """The name of the MJCF actuator that drives ``joint``, if one does."""
    for a in range(model.nu):
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT and int(model.actuator_trnid[a, 0]) == joint:
            return name_of(model, mujoco.mjtObj.mjOBJ_ACTUATOR, a, "actuator")
    return None

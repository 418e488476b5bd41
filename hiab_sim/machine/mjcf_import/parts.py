"""Machine-file entries of an imported MJCF: links with their joint frames, chains with their pivots, the TCP.

Conventions and units in :mod:`hiab_sim.machine.mjcf_import.importer`; every entry is a
:class:`~hiab_sim.machine.mjcf_import.frames.Note` (value and its MJCF origin).
"""

from __future__ import annotations

import re
from typing import Any

import mujoco
import numpy as np

from hiab_sim.machine.mjcf_import.chains import Role, in_plane_angle
from hiab_sim.machine.mjcf_import.frames import Frames, Imported, Note
from hiab_sim.machine.mjcf_import.graph import UnsupportedMJCFError, actuator_on, name_of
from hiab_sim.machine.parts import rot_z

#: Name of the root link: the world body and everything welded or locked to it.
ROOT = "ground"
Frame = tuple[np.ndarray, float]  # origin (3,) in machine coordinates [m], angle about z [rad]


def _local(frame: Frame, p: np.ndarray) -> list[float]:
    return [float(v) for v in np.array(rot_z(frame[1])).T @ (np.asarray(p) - frame[0])]


def emla_name(name: str) -> str:
    """The EMLA name of an MJCF actuator: its name with every character that cannot be in an identifier as ``_``.

    An EMLA file keys its actuators by identifiers (:func:`hiab_sim.emla.config.load_emla_set`).
    """
    out = re.sub(r"\W", "_", name)
    return out if out.isidentifier() else f"_{out}"


def emla_note(name: str) -> Note:
    """The ``emla`` entry of an actuator named ``name`` in the MJCF, with its origin."""
    renamed = "" if emla_name(name) == name else f" '{name}' as an identifier"
    return Note(emla_name(name), f"the actuator's name{renamed} (edit: the EMLA in your EMLA file)")


def proposed_bounds(low: float, high: float, value: float) -> list[float]:
    """Bounds proposed around ``value`` [m], rounded to 1e-9 m (no float noise) and still holding ``value``.

    A bound like 0.8200000000000001 (a stroke from a slide range) would refuse the 1 mm rounded
    design 0.82 that ``optimize`` reports for an optimum at that bound.
    """
    return [min(round(low, 9), value), max(round(high, 9), value)]


def group_name(imported: Imported, g: int) -> str:
    """The link name of a group: ``world`` for the root, else its first MJCF body's name."""
    if g == 0:
        return ROOT
    body = imported.mech.bodies(g)[0]
    return name_of(imported.mech.model, mujoco.mjtObj.mjOBJ_BODY, body, "body")


def link_entries(imported: Imported, frames: Frames, roles: list[Role]) -> tuple[dict[str, Any], dict[int, Frame]]:
    """Links (root first, parents before children) and each main group's machine frame at the reference pose."""
    mech, model = imported.mech, imported.mech.model
    own = {g for r in roles for g in r.own_groups}
    driven = {r.driven for r in roles}
    in_loops = {k for r in roles for k in r.block.edges}
    parent_edge = {e.b: k for k, e in enumerate(mech.edges) if e.kind != "pin"}
    link_frames: dict[int, Frame] = {0: (np.zeros(3), 0.0)}
    root_bodies = frames.bodies(0, np.zeros(3), 0.0)
    links: dict[str, Any] = {ROOT: {"bodies": root_bodies} if root_bodies else {}}
    problems = []
    failed: set[int] = set()  # groups already reported: what hangs on them is not reported again
    for g in range(1, mech.n_groups):
        if g in own:
            continue
        k = parent_edge[g]
        edge = mech.edges[k]
        j = edge.index
        if edge.a not in link_frames:
            if edge.a not in failed:
                problems.append(f"{edge.element}: its body hangs on a chain body (cylinder, rod, rocker or coupler)")
            failed.add(g)
            continue
        failed.add(g)  # until its link is written below
        if edge.kind == "hinge" and k not in driven:
            problems.append(f"{edge.element}: no actuated closed chain drives it")
            continue
        if edge.kind == "slide" and k in in_loops:
            problems.append(f"{edge.element}: a slide inside a loop that is not its actuator")
            continue
        parent_origin, parent_angle = link_frames[edge.a]
        jname = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
        qref = float(imported.qpos_ref[model.jnt_qposadr[j]])
        origin = frames.point(frames.data.xanchor[j])
        low, high = (float(v) for v in model.jnt_range[j])
        if edge.kind == "hinge":
            kappa = float(np.sign(frames.data.xaxis[j] @ mech.normal))
            angle = parent_angle + kappa * qref
            joint_origin = origin
            frame_angle = 0.0
            kind, where = (
                "revolute",
                f"{edge.element}: hinge, q = {kappa:+g} qpos (axis along {'+' if kappa > 0 else '-'}normal)",
            )
            if not model.jnt_limited[j]:
                problems.append(f"{edge.element}: a driven hinge needs a range (its working range)")
                continue
            span = sorted((kappa * low, kappa * high))
            imported.joint_map.append((j, kappa, 0.0))
            range_origin = f"{edge.element} range [{low:g}, {high:g}] rad times {kappa:+g}"
        else:
            if not model.jnt_limited[j]:
                problems.append(f"{edge.element}: a prismatic joint needs a range (its stroke)")
                continue
            w = frames.point(frames.data.xaxis[j])
            angle = in_plane_angle(w)
            joint_origin = origin - w * (qref - low)
            frame_angle = angle - parent_angle
            kind, where = (
                "prismatic",
                f"{edge.element}: slide, q = qpos - {low:g} (the stroke from its range's lower end)",
            )
            span = [0.0, high - low]
            imported.joint_map.append((j, 1.0, -low))
            range_origin = f"{edge.element} range [{low:g}, {high:g}] m, shifted to start at 0"
        link_frames[g] = (origin, angle)
        joint_frame: dict[str, Any] = {
            "r": Note(
                _local((parent_origin, parent_angle), joint_origin), f"{edge.element} anchor in the parent's frame"
            )
        }
        if frame_angle != 0.0:
            joint_frame["angle"] = Note(float(frame_angle), f"{edge.element} axis direction in the parent's frame")
        bodies = frames.bodies(g, origin, angle)
        name = group_name(imported, g)
        if not bodies:
            problems.append(f"body '{name}': a moving link needs mass")
            continue
        failed.discard(g)
        links[name] = {
            "parent": Note(group_name(imported, edge.a), "the parent body in the MJCF tree"),
            "joint": Note(jname, edge.element),
            "kind": Note(kind, where),
            "joint_frame": joint_frame,
            "joint_range": Note([float(v) for v in span], range_origin),
            "bodies": bodies,
        }
    if problems:
        raise UnsupportedMJCFError(problems)
    return links, link_frames


def _one_body(parts: dict[str, Any], origin: str) -> Any:
    """Several bodies of one group as one rigid body (sum of masses, parallel axes)."""
    if not parts:
        return None
    values = [p.value for p in parts.values()]
    mass = sum(v["mass"] for v in values)
    com = sum(v["mass"] * np.asarray(v["com"]) for v in values) / mass
    inertia = np.zeros((3, 3))
    for v in values:
        d = np.asarray(v["com"]) - com
        inertia += np.asarray(v["inertia"]) + v["mass"] * (float(d @ d) * np.eye(3) - np.outer(d, d))
    names = ", ".join(f"'{n}'" for n in parts)
    value = {"mass": float(mass), "com": [float(c) for c in com], "inertia": [[float(x) for x in r] for r in inertia]}
    return Note(value, f"body {names}: mass, centre of mass and inertia in the {origin} frame")


def chain_entry(
    imported: Imported, frames: Frames, role: Role, link_frames: dict[int, Frame]
) -> tuple[str, dict[str, Any]]:
    """One chain's entry (triangle or linkage) with its proposed decision variables."""
    mech, model = imported.mech, imported.mech.model
    slide = mech.edges[role.slide]
    j = slide.index
    jname = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
    name = actuator_on(model, j) or jname
    a = frames.edge_point(role.base_edge, role.base_group)
    b = frames.edge_point(role.end_edge, role.end_group)
    d = (b - a)[:2]
    s_ref = float(np.linalg.norm(d))
    u = np.array([*(d / s_ref), 0.0])
    psi = in_plane_angle(u)
    w = frames.point(frames.data.xaxis[j])
    kappa = float(w @ u)
    if abs(abs(kappa) - 1.0) > 1e-6:
        raise UnsupportedMJCFError([f"{slide.element}: the slide axis is not along the line of its two pins"])
    kappa = float(np.sign(kappa))
    if not model.jnt_limited[j]:
        raise UnsupportedMJCFError([f"{slide.element}: an actuator slide needs a range (its stroke)"])
    low, high = (float(v) for v in model.jnt_range[j])
    qref = float(imported.qpos_ref[model.jnt_qposadr[j]])
    x0 = s_ref + kappa * ((low if kappa > 0 else high) - qref)
    stroke = high - low
    if not x0 > stroke:
        raise UnsupportedMJCFError(
            [
                f"{slide.element}: retracted pin-to-pin length x0 = {x0:.6g} m is not longer than the stroke "
                f"{stroke:.6g} m (range [{low:g}, {high:g}]): a rod of at least the stroke must fit in x0"
            ]
        )
    rod_origin = frames.point(frames.data.xpos[mech.bodies(role.rod)[0]])
    lc = float((b - rod_origin)[:2] @ u[:2])
    lc_origin = f"body '{group_name(imported, role.rod)}' origin to the rod-end pin along the actuator"
    if not stroke <= lc < x0:
        lc = max(stroke, 0.5 * x0)  # < x0, as stroke < x0
        lc_origin = "chosen (the rod body's origin gives no Lc in [stroke, x0)): max(stroke, x0/2)"
    imported.actuators.append((j, kappa))
    cylinder = _one_body(frames.bodies(role.cylinder, a, psi), "cylinder")
    rod_at = a + (s_ref - lc) * u
    rod = _one_body(frames.bodies(role.rod, np.array([rod_at[0], rod_at[1], a[2]]), psi), "rod")
    hinge = frames.point(frames.data.xanchor[mech.edges[role.driven].index])

    def pivot(group: int, p: np.ndarray, edge: int) -> dict[str, Any]:
        return {
            "link": Note(group_name(imported, group), mech.edges[edge].element),
            "position": Note(_local(link_frames[group], p), f"{mech.edges[edge].element} pin in the link frame"),
        }

    joint = name_of(model, mujoco.mjtObj.mjOBJ_JOINT, mech.edges[role.driven].index, "joint")
    range_text = f"{slide.element} range [{low:g}, {high:g}]"
    actuator: dict[str, Any] = {
        "stroke": Note(stroke, f"{range_text}: max - min"),
        "piston_offset": Note(x0 - lc, "x0 - Lc"),
        "rod_length": Note(lc, lc_origin),
        "emla": emla_note(name),
        "body_scaling": Note("fixed", "chosen: an imported body's shape is unknown, so it does not rescale"),
    }
    if cylinder is not None:
        actuator["cylinder_body"] = cylinder
    if rod is not None:
        actuator["rod_body"] = rod
    x0_origin = f"{range_text}: pin-to-pin length at the retracted end (x0 = {x0:.6g} m)"
    entry: dict[str, Any] = {"kind": None, "joint": Note(joint, mech.edges[role.driven].element)}
    if role.kind == "triangle":
        entry["kind"] = Note("triangle", f"loop of {slide.element}, its two pins and {mech.edges[role.driven].element}")
        entry["pivots"] = {
            "base": pivot(role.base_group, a, role.base_edge),
            "end": pivot(role.end_group, b, role.end_edge),
        }
        entry["actuator"] = actuator
        hinge_distance = float(np.linalg.norm((a - hinge)[:2]))
        entry["variables"] = _triangle_variables(hinge_distance, x0 - lc, lc, stroke, x0_origin)
        return name, entry
    r = frames.edge_point(role.rocker_edge, role.base_group)
    h = frames.edge_point(role.link_edge, role.rocker)
    c_group = mech.edges[role.driven].b
    c = frames.edge_point(role.coupler_edge, c_group)
    cross = (c - r)[0] * (h - r)[1] - (c - r)[1] * (h - r)[0]
    side = 1 if float(cross) > 0.0 else -1
    rocker_len, coupler_len = float(np.linalg.norm((h - r)[:2])), float(np.linalg.norm((c - h)[:2]))
    rocker = _one_body(frames.bodies(role.rocker, r, in_plane_angle(h - r)), "rocker")
    coupler = _one_body(frames.bodies(role.coupler, np.array([h[0], h[1], r[2]]), in_plane_angle(c - h)), "coupler")
    linkage: dict[str, Any] = {
        "rocker_length": Note(
            rocker_len, f"{mech.edges[role.rocker_edge].element} to {mech.edges[role.link_edge].element}"
        ),
        "coupler_length": Note(
            coupler_len, f"{mech.edges[role.link_edge].element} to {mech.edges[role.coupler_edge].element}"
        ),
        "pin_side": Note(side, "the side of rocker -> coupler pivots the pin H is on at the reference pose"),
    }
    if rocker is not None:
        linkage["rocker_body"] = rocker
    if coupler is not None:
        linkage["coupler_body"] = coupler
    entry["kind"] = Note("linkage", f"four-bar driven by {slide.element} on its rocker-coupler pin")
    entry["pivots"] = {
        "base": pivot(role.base_group, a, role.base_edge),
        "rocker": pivot(role.base_group, r, role.rocker_edge),
        "coupler": pivot(c_group, c, role.coupler_edge),
    }
    entry["linkage"] = linkage
    entry["actuator"] = actuator
    base = _local(link_frames[role.base_group], a)
    span = PIVOT_SPAN_M(x0)
    proposed = "proposed: +-10 % of x0 around the imported value; edit"
    entry["variables"] = {
        "base_x": Note(
            {"kind": "pivot_x", "pivot": "base", "bounds": proposed_bounds(base[0] - span, base[0] + span, base[0])},
            proposed,
        ),
        "base_y": Note(
            {"kind": "pivot_y", "pivot": "base", "bounds": proposed_bounds(base[1] - span, base[1] + span, base[1])},
            proposed,
        ),
        "retracted_length": Note(
            {"kind": "retracted_length", "bounds": proposed_bounds(0.9 * x0, 1.1 * x0, x0)},
            "proposed: +-10 % of " + x0_origin,
        ),
    }
    return name, entry


def PIVOT_SPAN_M(x0: float) -> float:
    """Half-width of a proposed pivot coordinate's bounds: 10 % of the retracted length [m]."""
    return 0.1 * x0


def _triangle_variables(hinge_distance: float, lc0: float, lc: float, stroke: float, x0_origin: str) -> dict[str, Any]:
    """The seed's xi = [L, Lc0, Lc] with bounds around the imported values (proposed; edit them)."""
    out: dict[str, Any] = {}
    if hinge_distance > 1e-6:
        out["hinge_distance"] = Note(
            {
                "kind": "hinge_distance",
                "pivot": "base",
                "bounds": proposed_bounds(0.85 * hinge_distance, 1.15 * hinge_distance, hinge_distance),
            },
            f"proposed: +-15 % of the base pin's distance from the hinge ({hinge_distance:.6g} m); edit",
        )
    out["piston_offset"] = Note(
        {"kind": "piston_offset", "bounds": proposed_bounds(0.7 * lc0, 1.3 * lc0, lc0)},
        f"proposed: +-30 % of Lc0; {x0_origin}",
    )
    out["rod_length"] = Note(
        {"kind": "rod_length", "bounds": proposed_bounds(max(stroke, 0.7 * lc), 1.3 * lc, lc)},
        "proposed: +-30 % of Lc, not below the stroke",
    )
    return out


def tcp_entry(imported: Imported, frames: Frames, link_frames: dict[int, Frame], tcp: str | None) -> dict[str, Any]:
    """The TCP: the named site or body (default: a site called ``tcp``) in its link's frame."""
    mech, model, data = imported.mech, imported.mech.model, frames.data
    name = tcp or "tcp"
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)
    if site >= 0:
        body, p, rot, what = int(model.site_bodyid[site]), data.site_xpos[site], data.site_xmat[site], f"site '{name}'"
    else:
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        if body < 0:
            hint = "" if tcp else ": name it with --tcp SITE_OR_BODY"
            raise UnsupportedMJCFError([f"--tcp {name}: the MJCF has no site or body '{name}'{hint}"])
        p, rot, what = data.xpos[body], data.xmat[body], f"body '{name}'"
    group = mech.group_of_body[body]
    if group not in link_frames:
        raise UnsupportedMJCFError([f"{what}: the TCP must be on a machine link, not on a chain body"])
    xmat = data.xmat[body].reshape(3, 3)
    imported.tcp = (body, xmat.T @ (np.asarray(p) - data.xpos[body]))
    frame = link_frames[group]
    rotation = np.array(rot_z(frame[1])).T @ frames.axes.T @ np.asarray(rot).reshape(3, 3)
    return {
        "link": Note(group_name(imported, group), f"{what}: the link it is on"),
        "r": Note(_local(frame, frames.point(p)), f"{what} position in the link frame"),
        "R": Note([[float(x) for x in row] for row in rotation], f"{what} orientation in the link frame"),
    }

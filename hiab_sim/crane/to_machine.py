"""Converter from the lab-crane description :class:`~hiab_sim.crane.description.Crane` to a generic :class:`Machine`.

Temporary, until every caller uses :mod:`hiab_sim.machine`.

The crane's two triangle chains and its telescope map onto the generic description one to one:

* each boom is a revolute link whose joint frame sits at the boom hinge with rotation
  Rz(base_axis_angle - joint_offset), so its joint coordinate is the crane's theta and its frame
  is the crane's boom frame;
* each chain is a ``triangle`` with the base pivot on the chain's parent link at the cylinder
  base pivot and the end pivot at (L1, 0, 0) on the boom; its decision variables are the seed's
  xi = [L, Lc0, Lc] (``hinge_distance`` of the base pivot, ``piston_offset``, ``rod_length``);
* the telescope is a prismatic link whose joint frame is the cylinder frame moved by the rod
  offset along its x axis, driven by a ``direct`` chain; the end mass rides on it.

The bounds of the decision variables are not part of a crane file; the caller gives them.
"""

from __future__ import annotations

import numpy as np

from hiab_sim.crane import names
from hiab_sim.crane.description import ClosedChain, Crane
from hiab_sim.hydraulics.cylinders import HydraulicSystem
from hiab_sim.machine.chains import Actuator, Chain, DecisionVariable, Pivot
from hiab_sim.machine.description import Link, Machine
from hiab_sim.machine.parts import Pose, RigidBody, mat3, rot_z, vec3

#: Bounds of [L, Lc0, Lc] per chain used when none are given [m] (the shipped XS 031 studies').
DEFAULT_BOUNDS: dict[str, tuple[tuple[float, float], ...]] = {
    names.LIFT: ((0.80, 1.25), (0.04, 0.30), (0.60, 1.00)),
    names.TILT: ((0.90, 1.35), (0.04, 0.30), (0.60, 1.00)),
}


def _bodies(crane: Crane, link: str) -> tuple[RigidBody, ...]:
    return tuple(RigidBody(b.name, b.mass, b.com, b.inertia) for b in crane.bodies if b.link == link)


def _body(crane: Crane, link: str) -> RigidBody | None:
    found = _bodies(crane, link)
    return found[0] if found else None


def _boom(crane: Crane, chain: ClosedChain, joint: str) -> Link:
    return Link(
        name=names.boom_link(chain.name),
        parent=chain.parent,
        joint=joint,
        joint_kind="revolute",
        joint_frame=Pose(vec3(chain.boom_hinge), rot_z(chain.base_axis_angle - chain.joint_offset)),
        joint_range=chain.joint_range,
        parts=_bodies(crane, names.boom_link(chain.name)),
    )


def _triangle(crane: Crane, chain: ClosedChain, joint: str, bounds: tuple[tuple[float, float], ...]) -> Chain:
    xi = chain.default_lengths
    kinds = (("L", "hinge_distance", "base"), ("Lc0", "piston_offset", None), ("Lc", "rod_length", None))
    return Chain(
        name=chain.name,
        kind="triangle",
        joint=joint,
        actuator=Actuator(
            stroke=chain.stroke,
            piston_offset=xi.Lc0,
            rod_length=xi.Lc,
            emla=chain.name,
            hydraulic_cylinder=chain.name if crane.hydraulic_cylinders is not None else None,
            cylinder_body=_body(crane, names.cylinder_link(chain.name)),
            rod_body=_body(crane, names.rod_link(chain.name)),
            body_scaling="slender",
        ),
        pivots=(
            Pivot("base", chain.parent, chain.cylinder_base_pivot),
            Pivot("end", names.boom_link(chain.name), (chain.L1, 0.0, 0.0)),
        ),
        variables=tuple(
            DecisionVariable(chain.name, name, kind, pivot, low, high)
            for (name, kind, pivot), (low, high) in zip(kinds, bounds, strict=True)
        ),
    )


def _hydraulic(cylinders: HydraulicSystem | None) -> HydraulicSystem | None:
    """The crane file's cylinders as a machine file's ``hydraulic`` section (its error messages' prefix)."""
    if cylinders is None:
        return None
    return HydraulicSystem(
        cylinders=cylinders.cylinders,
        supply_pressure=cylinders.supply_pressure,
        coulomb_friction=cylinders.coulomb_friction,
        viscous_friction=cylinders.viscous_friction,
    )


def machine_from_crane(
    crane: Crane,
    joints: tuple[str, str, str] = (names.THETA1, names.THETA2, names.XT2),
    bounds: dict[str, tuple[tuple[float, float], ...]] | None = None,
) -> Machine:
    """The crane as a generic :class:`Machine` (same numbers; see the module docstring)."""
    chosen = DEFAULT_BOUNDS if bounds is None else bounds
    tele = crane.telescope
    cyl = np.asarray(tele.cylinder_frame.rotation)
    slide_origin = np.asarray(tele.cylinder_frame.position) + cyl @ np.array([tele.rod_offset, 0.0, 0.0])
    links = (
        Link(names.BASE, None, "base_mount", "fixed", Pose((0.0, 0.0, 0.0)), None, _bodies(crane, names.BASE)),
        _boom(crane, crane.lift, joints[0]),
        _boom(crane, crane.tilt, joints[1]),
        Link(
            name=names.TELESCOPE_ROD,
            parent=tele.parent,
            joint=joints[2],
            joint_kind="prismatic",
            joint_frame=Pose(vec3(slide_origin), mat3(cyl)),
            joint_range=tele.joint_range,
            parts=_bodies(crane, names.TELESCOPE_ROD),
        ),
    )
    telescope = Chain(
        name=names.TELESCOPE,
        kind="direct",
        joint=joints[2],
        actuator=Actuator(
            stroke=tele.stroke,
            piston_offset=None,
            rod_length=None,
            emla=names.TELESCOPE,
            hydraulic_cylinder=names.TELESCOPE if crane.hydraulic_cylinders is not None else None,
        ),
    )
    return Machine(
        name=crane.name,
        source=crane.source,
        gravity=crane.gravity,
        links=links,
        chains=(
            _triangle(crane, crane.lift, joints[0], chosen[names.LIFT]),
            _triangle(crane, crane.tilt, joints[1], chosen[names.TILT]),
            telescope,
        ),
        tcp_link=names.TELESCOPE_ROD,
        tcp=Pose(crane.tcp_in_telescope_rod.position, crane.tcp_in_telescope_rod.rotation),
        hydraulic=_hydraulic(crane.hydraulic_cylinders),
    )

"""The design-dependent numbers of the Newton-Euler solve, for many designs at once.

A design (:meth:`hiab_sim.machine.description.Machine.with_design`) moves chain pivots, sets
piston offsets Lc0 and rod lengths Lc, and scales slender actuator bodies; nothing else of the
tree changes. :func:`design_constants` applies the same rules (:mod:`hiab_sim.machine.design`)
to D designs (D, n_xi) in one vectorised pass and returns the planar numbers of
:func:`hiab_sim.machine.dynamics.planar.planar_bodies` and of the loop pins that depend on them
(:class:`~hiab_sim.machine.dynamics.ne_layout.NeConstants`), without building D machines. Per chain with variables:

* pivots: ``hinge_distance`` d puts the pivot at h + d (p - h) / |p - h| (h the chain's hinge in
  the pivot's link frame), ``pivot_x``/``pivot_y`` set a coordinate, in the chain's variable order;
* Lc0, Lc from ``piston_offset``, ``rod_length``; ``retracted_length`` x0 sets Lc = x0 - Lc0;
* slender bodies (:meth:`hiab_sim.machine.parts.RigidBody.scaled_slender`): the cylinder's factor
  f = x0 / x0_file, the rod's f = Lc / Lc_file; m and the centre of mass scale with f, the inertia
  with f^3 but its axial entry I_xx with f, so in the plane I_zz(f) = f^3 I_zz + (f - f^3) I_xx F_zx^2
  (F the body's frame rotation at zero coordinates).

Positions in a body's planar frame are (F r)_xy; a loop pin's point on its actuator body also
carries the pins' out-of-plane offset dz (:mod:`hiab_sim.machine.dynamics.tree`), which moves
with the pivots. Tests hold these numbers to those of the designed machine's tree (1e-14).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.ne_layout import NeConstants, NeLayout
from hiab_sim.machine.dynamics.tree import world_z

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]


def _xy(fixed: Array, r: Array) -> Complex:
    """Planar coordinates (F r)_xy of points r (D, 3) [m], complex (D,)."""
    out: Complex = (r @ fixed[0]) + 1j * (r @ fixed[1])
    return out


def design_constants(machine: Machine, layout: NeLayout, designs: Array) -> NeConstants:
    """The numbers of designs (D, n_xi) in ``machine.decision_variables`` order (see the module docstring).

    ``layout`` must be :func:`~hiab_sim.machine.dynamics.ne_layout.layout_of` ``(machine)``. No
    bounds are checked (a finite-difference stencil may step over one); use
    :meth:`Machine.with_design` for a checked design.

    Raises:
        InvalidInputError: a shape other than (D, n_xi), a NaN or inf, or a design whose piston
            offset, rod or retracted length is not > 0 (field ``designs``).

    """
    designs = np.atleast_2d(np.asarray(designs, dtype=float))
    variables = machine.decision_variables
    if designs.ndim != 2 or designs.shape[1] != len(variables):
        need = f"must be (D, {len(variables)}): {machine.variable_keys}"
        raise InvalidInputError("designs", f"shape {designs.shape}", need, "m")
    if not np.all(np.isfinite(designs)):
        raise InvalidInputError("designs", "NaN or inf", "must be finite", "m")
    base = layout.file
    D = designs.shape[0]
    out = {name: np.repeat(getattr(base, name).T, D, axis=0) for name in NeConstants.__dataclass_fields__}
    z_of_link = world_z(machine)
    for c, chain in enumerate(machine.chains):
        columns = [(v, designs[:, k]) for k, v in enumerate(variables) if v.chain == chain.name]
        if columns:
            _chain_numbers(machine, layout, z_of_link, c, columns, out)
    return NeConstants(**{name: np.ascontiguousarray(value.T) for name, value in out.items()})


def _chain_numbers(
    machine: Machine,
    layout: NeLayout,
    z_of_link: dict[str, tuple[float, Array]],
    c: int,
    columns: list[tuple[object, Array]],
    out: dict[str, Array],
) -> None:
    """Write chain c's numbers for its variable columns into ``out`` (arrays (D, ...))."""
    chain = machine.chains[c]
    tree, planar = layout.tree, layout.planar
    act = chain.actuator
    D = columns[0][1].shape[0]
    piston = np.full(D, np.nan if act.piston_offset is None else act.piston_offset)
    rod = np.full(D, np.nan if act.rod_length is None else act.rod_length)
    pos = {p.role: np.tile(np.asarray(p.position, dtype=float), (D, 1)) for p in chain.pivots}
    retracted = None
    for v, value in columns:
        kind = v.kind  # type: ignore[attr-defined]
        if kind == "piston_offset":
            piston = value
        elif kind == "rod_length":
            rod = value
        elif kind == "retracted_length":
            retracted = value
        else:
            role = str(v.pivot)  # type: ignore[attr-defined]
            p = pos[role].copy()
            if kind == "pivot_x":
                p[:, 0] = value
            elif kind == "pivot_y":
                p[:, 1] = value
            else:
                hinge = machine.hinge_xy(chain, chain.pivot(role).link)
                d = p[:, :2] - hinge
                p[:, :2] = hinge + value[:, None] * d / np.linalg.norm(d, axis=1)[:, None]
            pos[role] = p
    if retracted is not None:
        rod = retracted - piston
    if chain.kind == "direct":
        return
    for label, values in (("piston offset", piston), ("rod length", rod), ("retracted length", piston + rod)):
        if np.any(values <= 0.0):
            raise InvalidInputError("designs", f"chain {chain.name}: a {label} <= 0", "must be > 0", "m")
    frame = {role: layout.fixed[tree.index(chain.pivot(role).link)] for role in pos}

    def height(role: str) -> Array:  # world z of a pivot at zero coordinates [m]
        origin, rotation = z_of_link[chain.pivot(role).link]
        return origin + pos[role] @ rotation[2]

    cyl = tree.index(f"{chain.name}.cylinder")
    rod_body = cyl + 1
    F = frame["base"]  # the cylinder's and the rod's frame
    ax, az = complex(F[0, 0], F[1, 0]), complex(F[0, 2], F[1, 2])
    out["origin"][:, cyl] = _xy(F, pos["base"])
    out["origin"][:, rod_body] = piston * ax
    out["x0"][:, c] = piston + rod
    if chain.kind == "triangle":
        k = next(k for k, p in enumerate(tree.loops) if p.body_a == rod_body)
        out["point_a"][:, k] = rod * ax + (height("end") - height("base")) * az
        out["point_b"][:, k] = _xy(frame["end"], pos["end"])
    else:
        linkage = chain.linkage
        if linkage is None:
            raise AssertionError("a linkage chain carries its four-bar")
        rocker = cyl + 2
        out["origin"][:, rocker] = _xy(frame["rocker"], pos["rocker"])
        k_rod = next(k for k, p in enumerate(tree.loops) if p.body_a == rod_body)
        out["point_a"][:, k_rod] = rod * ax + (height("rocker") - height("base")) * az
        R = frame["rocker"]  # the rocker's and the coupler's frame
        k = next(k for k, p in enumerate(tree.loops) if p.body_a == rocker + 1)
        reach = linkage.coupler_length * complex(R[0, 0], R[1, 0])
        out["point_a"][:, k] = reach + (height("coupler") - height("rocker")) * complex(R[0, 2], R[1, 2])
        out["point_b"][:, k] = _xy(frame["coupler"], pos["coupler"])
    x0_file, rod_file = act.retracted_length, act.rod_length
    if act.body_scaling != "slender" or x0_file is None or rod_file is None:
        return
    for b, body, factor in ((cyl, act.cylinder_body, (piston + rod) / x0_file), (rod_body, act.rod_body, rod / rod_file)):
        if body is None:
            continue
        axial = float(body.inertia[0][0]) * float(layout.fixed[b][2, 0]) ** 2
        p = planar[b]
        out["mass"][:, b] = p.mass * factor
        out["com"][:, b] = p.com * factor
        out["izz"][:, b] = factor**3 * (p.inertia_zz - axial) + factor * axial

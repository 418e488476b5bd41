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

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.dynamics.ne_layout import NeConstants, NeLayout
from hiab_sim.machine.dynamics.tree import world_z

Complex = NDArray[np.complex128]


def _xy(fixed: Array, r: Array) -> Complex:
    """Planar coordinates (F r)_xy of points r (D, 3) [m], complex (D,)."""
    out: Complex = (r @ fixed[0]) + 1j * (r @ fixed[1])
    return out


@dataclass(frozen=True)
class _Body:
    """A slender actuator body: its index, file mass [kg], planar centre of mass [m], I_zz and I_xx F_zx^2 [kg m^2]."""

    index: int
    mass: float
    com: complex
    izz: float
    axial: float


@dataclass(frozen=True)
class _ChainPlan:
    """What a design changes of one chain, and where it goes (built once per machine).

    ``columns``: (design column, kind, pivot role, the chain's hinge in the pivot's link frame);
    per pivot role its file position, its link's planar frame F and (world z of the link origin,
    third row of its rotation) at zero coordinates; body and pin indices; the slender bodies.
    """

    chain: int
    name: str
    kind: str
    columns: tuple[tuple[int, str, str, Array | None], ...]
    position: dict[str, Array]
    frame: dict[str, Array]
    height: dict[str, tuple[float, Array]]
    piston: float
    rod: float
    cyl: int
    end_pin: int
    rocker: int
    coupler_pin: int
    coupler_length: float
    scaled: tuple[tuple[_Body | None, _Body | None], ...]  # ((cylinder, rod),) when the bodies are slender
    affine: bool  # no pivot is set both by a hinge distance and by a coordinate


def _plans(machine: Machine, layout: NeLayout) -> tuple[_ChainPlan, ...]:
    """The chains with decision variables, compiled (cached in the layout)."""
    cached = layout.memo.get("design plans")
    if isinstance(cached, tuple):
        return cached
    tree, planar = layout.tree, layout.planar
    heights = world_z(machine)
    plans = []
    for c, chain in enumerate(machine.chains):
        columns = tuple(
            (k, v.kind, str(v.pivot), machine.hinge_xy(chain, chain.pivot(str(v.pivot)).link) if v.pivot else None)
            for k, v in enumerate(machine.decision_variables)
            if v.chain == chain.name
        )
        if not columns or chain.kind == "direct":
            continue
        act = chain.actuator
        cyl = tree.index(f"{chain.name}.cylinder")
        loops = {p.body_a: k for k, p in enumerate(tree.loops)}
        scaled: tuple[tuple[_Body | None, _Body | None], ...] = ()
        if act.body_scaling == "slender":
            pair = []
            for b, body in ((cyl, act.cylinder_body), (cyl + 1, act.rod_body)):
                axial = 0.0 if body is None else float(body.inertia[0][0]) * float(layout.fixed[b][2, 0]) ** 2
                p = planar[b]
                pair.append(None if body is None else _Body(b, p.mass, p.com, p.inertia_zz, axial))
            scaled = ((pair[0], pair[1]),)
        linkage = chain.linkage
        plans.append(
            _ChainPlan(
                chain=c,
                name=chain.name,
                kind=chain.kind,
                columns=columns,
                position={p.role: np.asarray(p.position, dtype=float) for p in chain.pivots},
                frame={p.role: layout.fixed[tree.index(p.link)] for p in chain.pivots},
                height={p.role: (heights[p.link][0], heights[p.link][1][2]) for p in chain.pivots},
                piston=float(act.piston_offset),  # type: ignore[arg-type]
                rod=float(act.rod_length),  # type: ignore[arg-type]
                cyl=cyl,
                end_pin=loops[cyl + 1],
                rocker=cyl + 2 if linkage is not None else -1,
                coupler_pin=loops[cyl + 3] if linkage is not None else -1,
                coupler_length=linkage.coupler_length if linkage is not None else 0.0,
                scaled=scaled,
                affine=not (
                    {role for _, kind, role, _ in columns if kind == "hinge_distance"}
                    & {role for _, kind, role, _ in columns if kind in ("pivot_x", "pivot_y")}
                ),
            )
        )
    layout.memo["design plans"] = out = tuple(plans)
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
    fit = _affine(machine, layout)
    if fit is None:
        out = _direct(machine, layout, designs)
    else:
        step = designs - fit.at
        out = {name: fit.base[name] + step @ fit.slope[name] for name in fit.base}
        lengths = fit.lengths[0] + step @ fit.lengths[1]  # (D, 3 per chain): Lc0, Lc, x0
        if np.any(lengths <= 0.0):
            for k, plan in enumerate(_plans(machine, layout)):
                _check_lengths(plan, lengths[:, 3 * k], lengths[:, 3 * k + 1])
        if fit.slender.size:  # I_zz(f) = f^3 (I_zz - I_xx F_zx^2) + f I_xx F_zx^2, f affine in the variables
            factor = fit.factor[0] + step @ fit.factor[1]
            out["izz"][:, fit.slender] = factor**3 * fit.cubic + factor * fit.linear
    return NeConstants(**{name: np.ascontiguousarray(value.T) for name, value in out.items()})  # type: ignore[arg-type]


@dataclass(frozen=True)
class _Fit:
    """Design numbers as base + (x - at) @ slope: exact, since each is affine in the variables.

    Pivots move along lines or on coordinates, Lc0 and Lc are variables or differences of
    them, masses and centres of mass scale with factors affine in them. Only the slender bodies'
    I_zz (cubic in its factor) is not: it is computed from the fitted lengths. A pivot set by
    both a hinge distance and a coordinate would not be affine (the description refuses such a
    pair); a plan with one would take :func:`_direct`.
    """

    at: Array
    base: dict[str, Array]
    slope: dict[str, Array]
    lengths: tuple[Array, Array]
    slender: NDArray[np.intp]
    factor: tuple[Array, Array]
    cubic: Array
    linear: Array


def _affine(machine: Machine, layout: NeLayout) -> _Fit | None:
    """The affine fit of the design numbers (cached in the layout), or None where it is not exact."""
    if "design fit" in layout.memo:
        cached = layout.memo["design fit"]
        return cached if isinstance(cached, _Fit) else None
    plans = _plans(machine, layout)
    fit = None
    if all(plan.affine for plan in plans):
        at = machine.design_values()
        n = at.shape[0]
        probe = at + np.vstack([np.zeros((1, n)), np.eye(n)])  # the file design and a unit step in each variable
        lengths: list[Array] = []
        out = _direct(machine, layout, probe, lengths)
        table = np.stack(lengths, axis=1) if lengths else np.zeros((n + 1, 0))
        bodies, factors = [], []
        for k, plan in enumerate(plans):
            piston, rod = table[:, 3 * k], table[:, 3 * k + 1]
            for cylinder, rod_part in plan.scaled:
                for body, factor in ((cylinder, (piston + rod) / (plan.piston + plan.rod)), (rod_part, rod / plan.rod)):
                    if body is not None:
                        bodies.append(body)
                        factors.append(factor)
        scale = np.stack(factors, axis=1) if factors else np.zeros((n + 1, 0))
        fit = _Fit(
            at=at,
            base={name: value[:1] for name, value in out.items()},
            slope={name: value[1:] - value[:1] for name, value in out.items()},
            lengths=(table[:1], table[1:] - table[:1]),
            slender=np.asarray([b.index for b in bodies], dtype=np.intp),
            factor=(scale[:1], scale[1:] - scale[:1]),
            cubic=np.asarray([b.izz - b.axial for b in bodies]),
            linear=np.asarray([b.axial for b in bodies]),
        )
    layout.memo["design fit"] = fit
    return fit


def _direct(machine: Machine, layout: NeLayout, designs: Array, lengths: list[Array] | None = None) -> dict[str, Array]:
    """The numbers (D, n) of each field, chain by chain by the rules of the module docstring."""
    base = layout.file
    D = designs.shape[0]
    out = {name: np.repeat(getattr(base, name).T, D, axis=0) for name in NeConstants.__dataclass_fields__}
    for plan in _plans(machine, layout):
        piston, rod = _chain_numbers(plan, designs, out)
        if lengths is not None:
            lengths.extend((piston, rod, piston + rod))
    return out


def _check_lengths(plan: _ChainPlan, piston: Array, rod: Array) -> None:
    for label, values in (("piston offset", piston), ("rod length", rod), ("retracted length", piston + rod)):
        if np.any(values <= 0.0):
            raise InvalidInputError("designs", f"chain {plan.name}: a {label} <= 0", "must be > 0", "m")


def _scale_inertia(plan: _ChainPlan, piston: Array, rod: Array, out: dict[str, Array]) -> None:
    """Slender bodies: m and the centre of mass scale with f, I_zz(f) = f^3 (I_zz - I_xx F_zx^2) + f I_xx F_zx^2."""
    for cylinder, rod_part in plan.scaled:
        for body, factor in ((cylinder, (piston + rod) / (plan.piston + plan.rod)), (rod_part, rod / plan.rod)):
            if body is None:
                continue
            out["mass"][:, body.index] = body.mass * factor
            out["com"][:, body.index] = body.com * factor
            out["izz"][:, body.index] = factor**3 * (body.izz - body.axial) + factor * body.axial


def _chain_numbers(plan: _ChainPlan, designs: Array, out: dict[str, Array]) -> tuple[Array, Array]:
    """Write one chain's numbers for D designs into ``out`` (arrays (D, ...)); return its Lc0 and Lc (D,) [m]."""
    D = designs.shape[0]
    piston, rod = np.full(D, plan.piston), np.full(D, plan.rod)
    pos = dict(plan.position)
    retracted = None
    for k, kind, role, hinge in plan.columns:
        value = designs[:, k]
        if kind == "piston_offset":
            piston = value
        elif kind == "rod_length":
            rod = value
        elif kind == "retracted_length":
            retracted = value
        else:
            p = np.array(np.broadcast_to(pos[role], (D, 3)))
            if kind == "pivot_x":
                p[:, 0] = value
            elif kind == "pivot_y":
                p[:, 1] = value
            elif hinge is not None:  # hinge_distance
                d = p[:, :2] - hinge
                p[:, :2] = hinge + value[:, None] * d / np.linalg.norm(d, axis=1)[:, None]
            pos[role] = p
    if retracted is not None:
        rod = retracted - piston
    x0 = piston + rod
    _check_lengths(plan, piston, rod)

    def height(role: str) -> Array:  # world z of a pivot at zero coordinates [m]
        origin, row = plan.height[role]
        return origin + pos[role] @ row

    cyl, rod_body = plan.cyl, plan.cyl + 1
    F = plan.frame["base"]  # the cylinder's and the rod's frame
    ax, az = complex(F[0, 0], F[1, 0]), complex(F[0, 2], F[1, 2])
    out["origin"][:, cyl] = _xy(F, np.atleast_2d(pos["base"]))
    out["origin"][:, rod_body] = piston * ax
    out["x0"][:, plan.chain] = x0
    if plan.kind == "triangle":
        out["point_a"][:, plan.end_pin] = rod * ax + (height("end") - height("base")) * az
        out["point_b"][:, plan.end_pin] = _xy(plan.frame["end"], np.atleast_2d(pos["end"]))
    else:
        out["origin"][:, plan.rocker] = _xy(plan.frame["rocker"], np.atleast_2d(pos["rocker"]))
        out["point_a"][:, plan.end_pin] = rod * ax + (height("rocker") - height("base")) * az
        R = plan.frame["rocker"]  # the rocker's and the coupler's frame
        reach = plan.coupler_length * complex(R[0, 0], R[1, 0])
        lift = (height("coupler") - height("rocker")) * complex(R[0, 2], R[1, 2])
        out["point_a"][:, plan.coupler_pin] = reach + lift
        out["point_b"][:, plan.coupler_pin] = _xy(plan.frame["coupler"], np.atleast_2d(pos["coupler"]))
    _scale_inertia(plan, piston, rod, out)
    return piston, rod

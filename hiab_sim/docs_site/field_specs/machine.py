"""The machine file's keys (:func:`hiab_sim.machine.loader.machine_from_dict`): links, chains, TCP, hydraulics.

Facts come from the code that owns them: types, defaults and descriptions from the dataclasses'
fields and ``Attributes:`` (``Machine``, ``Link``, ``Actuator``, ``Cylinder``), the allowed ranges
from the checks of their ``__post_init__`` by the field each check names
(:func:`~hiab_sim.docs_site.dataclass_fields.checked_fields`: ``Chain`` checks its actuator's and
four-bar's keys, ``HydraulicSystem`` its friction), the chain kinds, pivot roles and variable kinds
from :mod:`hiab_sim.machine.chains`. What only the loader handles (a body's ``inertia_zz``, a pose's
``angle``, which keys a root link may omit) is written here once, next to the loader's name.
"""

from __future__ import annotations

from dataclasses import replace

from hiab_sim.docs_site.dataclass_fields import checked_fields
from hiab_sim.docs_site.field_specs.rows import Key, free, from_class, interval, number, section, section_of, text

#: Shown for a vector the loader reads as (x, y) or (x, y, z) (``_vec3``: z defaults to 0).
POINT = "[x, y] or [x, y, z]"


def _checked(cls: type, prefix: str = "") -> dict[str, str]:
    """``key -> allowed`` of the checks of ``cls`` whose field name starts with ``prefix`` (prefix dropped)."""
    return {k.removeprefix(prefix): v for k, v in checked_fields(cls).items() if k.startswith(prefix)}


def _pose(required_r: bool) -> list[Key]:
    """A frame placement (the loader's ``_pose``): ``r``, and ``R`` or ``angle``; identity rotation by default."""
    from hiab_sim.machine.parts import Pose

    return [
        Key(
            "r",
            type=POINT,
            unit="m",
            default="required" if required_r else "[0, 0]",
            allowed=_checked(Pose)["r"],
            description="Origin of the frame in its parent's frame; z defaults to 0.",
        ),
        Key(
            "R",
            type="3x3 nested list",
            default="identity",
            allowed="a rotation matrix (|R R^T - I| <= 1e-6, det > 0); not with `angle`",
            description="Rotation parent -> frame.",
        ),
        number(
            "angle",
            "rad",
            "Rotation Rz(angle) about the plane normal instead of `R`.",
            allowed="finite; not with `R`",
            default="0",
        ),
    ]


def _body(where: str, description: str, default: str = "none") -> list[Key]:
    """A rigid body (the loader's ``_body``, a :class:`~hiab_sim.machine.parts.RigidBody`) at ``where``."""
    from hiab_sim.machine.parts import RigidBody

    checked = _checked(RigidBody)
    one = "exactly one of `inertia`, `inertia_zz`"
    keys = [
        number("mass", "kg", "Mass.", allowed=checked["mass"]),
        Key(
            "com",
            type=POINT,
            unit="m",
            allowed=checked["com"],
            description="Centre of mass in the body's frame; z defaults to 0.",
        ),
        Key(
            "inertia",
            type="3x3 nested list",
            unit="kg m^2",
            default=one,
            allowed="symmetric, eigenvalues > 0, I1 + I2 >= I3",
            description="Inertia about the centre of mass in the frame's axes.",
        ),
        number(
            "inertia_zz",
            "kg m^2",
            "Planar inertia Izz only; stored as the thin plate diag(Izz/2, Izz/2, Izz).",
            allowed="> 0",
            default=one,
        ),
    ]
    return section_of(where, description, keys, default)


def _links() -> list[Key]:
    """``links``: the link tree (:class:`hiab_sim.machine.description.Link`)."""
    from hiab_sim.machine.description import Link

    where = "links.<link>"
    rows = {k.path: k for k in from_class("", Link, skip=("name",))}
    checked = _checked(Link)
    moving = "required for a moving link"
    return [
        free("links", "Link name -> link; a tree with exactly one root (a link without `parent`).", "mapping"),
        section(where, "One link and the joint that carries it on its parent."),
        replace(rows["parent"], path=f"{where}.parent", default="none (the root)"),
        replace(rows["joint"], path=f"{where}.joint", default=f"{moving}; the root's: `<link>_mount`"),
        replace(
            rows["joint_kind"],
            path=f"{where}.kind",
            default=f"{moving}; the root's: `fixed`",
            allowed=checked["joint_kind"],
        ),
        *section_of(f"{where}.joint_frame", rows["joint_frame"].description, _pose(required_r=False), "identity"),
        replace(
            rows["joint_range"],
            path=f"{where}.joint_range",
            type="[number, number]",
            unit="rad or m",
            default=f"{moving}; none for the root",
            allowed=checked["joint_range"],
        ),
        free(f"{where}.bodies", rows["parts"].description + " Part name -> body.", "mapping"),
        *_body(f"{where}.bodies.<body>", "One rigid part, in the link's frame.", "required"),
    ]


def _chains() -> list[Key]:
    """``chains``: the actuated closed chains (:mod:`hiab_sim.machine.chains`)."""
    from hiab_sim.machine.chains import CHAIN_KINDS, PIVOT_ROLES, Actuator, Chain, DecisionVariable, Linkage, Pivot

    where = "chains.<chain>"
    chain = _checked(Chain)
    roles = "; ".join(f"{kind}: {', '.join(f'`{r}`' for r in PIVOT_ROLES[kind]) or 'none'}" for kind in CHAIN_KINDS)
    actuator = []
    for key in from_class("", Actuator):
        if key.path.endswith("_body"):
            frame = key.path.removesuffix("_body")
            actuator += _body(f"{where}.actuator.{key.path}", f"The actuator's {frame} body, in the {frame} frame.")
        else:
            allowed = chain.get(f"actuator.{key.path}", "")
            actuator.append(replace(key, path=f"{where}.actuator.{key.path}", allowed=allowed))
    lengths = {"allowed": "> 0 (triangle, linkage); >= 0 (direct)", "default": "required for a triangle, linkage"}
    actuator = [replace(k, **lengths) if k.path.endswith(("piston_offset", "rod_length")) else k for k in actuator]
    linkage = {k.path: k for k in from_class("", Linkage)}
    descriptions = {
        "rocker_length": ("m", "|H - rocker|: the rocker from its pivot on the parent to the pin H."),
        "coupler_length": ("m", "|H - coupler|: the coupler from H to its pivot on the driven link."),
        "pin_side": ("", "Side of the line rocker -> coupler that H lies on (+1: left)."),
    }
    variable = _checked(DecisionVariable)
    return [
        free(
            "chains",
            "Chain name (the actuator's name) -> chain; file order is the order of actuator samples.",
            "mapping",
        ),
        section(where, "One actuated closed chain driving one joint with one linear actuator."),
        text(f"{where}.kind", "How the actuator drives the joint.", allowed=chain["kind"]),
        text(f"{where}.joint", "The joint it drives: revolute for a triangle or linkage, prismatic for direct."),
        free(f"{where}.pivots", f"Role -> pivot; the roles of each kind: {roles}.", "mapping"),
        section(f"{where}.pivots.<role>", "One pin of the chain."),
        text(f"{where}.pivots.<role>.link", "The link the pin is on."),
        Key(
            f"{where}.pivots.<role>.position",
            type=POINT,
            unit="m",
            allowed=_checked(Pivot)["position"],
            description="Pin position in the link's frame; z is the out-of-plane offset of a 3D model.",
        ),
        section(f"{where}.actuator", "The linear actuator: pin-to-pin length s = piston_offset + rod_length + x."),
        *actuator,
        section(f"{where}.linkage", "The four-bar of a `linkage` chain (only there).", "required for a linkage"),
        *[
            replace(
                linkage[name],
                path=f"{where}.linkage.{name}",
                unit=unit,
                allowed=chain[f"linkage.{name}"],
                description=text,
            )
            for name, (unit, text) in descriptions.items()
        ],
        *_body(f"{where}.linkage.rocker_body", "The rocker's body, in the rocker frame (origin at its pivot, x to H)."),
        *_body(f"{where}.linkage.coupler_body", "The coupler's body, in the coupler frame (origin at H)."),
        free(f"{where}.variables", "Variable name (unique in the chain) -> decision variable.", "mapping"),
        section(f"{where}.variables.<variable>", "One design variable an optimisation may move."),
        text(f"{where}.variables.<variable>.kind", "What it sets.", allowed=variable["kind"]),
        text(
            f"{where}.variables.<variable>.pivot",
            "The pivot it moves.",
            default="none",
            allowed="a pivot role of the chain; required for `hinge_distance`, `pivot_x`, `pivot_y`, else none",
        ),
        interval(
            f"{where}.variables.<variable>.bounds",
            "m",
            "Bounds [low, high] of the variable.",
            allowed=variable["bounds"] + "; the file's own value within",
        ),
    ]


def _hydraulic() -> list[Key]:
    """``hydraulic``: the baseline cylinders (:class:`~hiab_sim.hydraulics.cylinders.HydraulicSystem`)."""
    from hiab_sim.hydraulics.cylinders import Cylinder, HydraulicSystem

    checked = _checked(HydraulicSystem)
    cylinder = from_class("", Cylinder, skip=("name", "pin_to_pin_at_zero", "counterbalance", "label"))
    cylinder = [replace(k, allowed="0 < rod < bore") if k.path == "rod" else k for k in cylinder]
    return [
        section("hydraulic", "The hydraulic cylinders the EMLAs replace (the hydraulic baseline).", "none"),
        free("hydraulic.cylinders", "Cylinder name (an actuator's `hydraulic_cylinder`) -> cylinder.", "mapping"),
        *section_of("hydraulic.cylinders.<cylinder>", "One double-acting single-rod cylinder.", cylinder),
        number("hydraulic.supply_pressure", "Pa", "System (relief) pressure p_s.", allowed=checked["supply_pressure"]),
        *section_of(
            "hydraulic.friction",
            "Seal friction of every cylinder.",
            [
                number(name, unit, text, allowed=checked[f"friction.{name}"], default="0")
                for name, unit, text in (
                    ("coulomb", "N", "Coulomb seal friction F_c opposing the rod velocity, per cylinder."),
                    ("viscous", "N s/m", "Viscous friction b, per cylinder."),
                )
            ],
            "none",
        ),
    ]


def machine_keys() -> list[Key]:
    """The machine file (:func:`hiab_sim.machine.loader.load_machine`), SI units, y up."""
    from hiab_sim.machine.description import Machine

    top = {k.path: k for k in from_class("", Machine)}
    workspace = _checked(Machine, "workspace.")
    return [
        top["name"],
        top["source"],
        top["gravity"],
        *_links(),
        *_chains(),
        *section_of(
            "tcp",
            "The TCP: its link and its frame there.",
            [text("link", top["tcp_link"].description), *_pose(required_r=True)],
        ),
        *_hydraulic(),
        *section_of(
            "workspace",
            top["workspace"].description,
            [
                interval(axis, "m", text, allowed=workspace[axis])
                for axis, text in (("x", "[x_min, x_max] of the TCP."), ("y", "[y_min, y_max] of the TCP."))
            ],
            "none",
        ),
        text(
            "realistic_plant",
            "The plant `hiab-sim simulate --plant realistic` runs on this machine's results: a shipped plant "
            "name or a plant file, read next to the machine file (docs/plant.md).",
            default="none (the shipped realistic plant)",
        ),
        Key("notes", type="text, list or mapping", default="none", description="Free provenance notes, not read."),
    ]

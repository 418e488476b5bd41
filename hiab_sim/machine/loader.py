"""Machine YAML -> validated :class:`~hiab_sim.machine.description.Machine` (a shipped name or a file).

The file format (every key, unit, default and range) is documented in ``docs/machine.md``. The
loader reads structure and types (:mod:`hiab_sim.yaml_fields`: unknown or missing keys, a word
where a number belongs raise :class:`ConfigError`); ranges and names are checked by the
dataclasses when they are built, and the assembly over the working ranges (a loop that cannot
close, a chain passing its toggle, a stroke shorter than the working range needs) by
:func:`hiab_sim.machine.kinematics.assembly.check_machine`; each raises a one-line
:class:`InvalidInputError` naming the field. The file's own values of its decision variables must
lie within their declared bounds.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from hiab_sim.checks import check_range
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.hydraulics.cylinders import HydraulicSystem, cylinder_from_mapping, system_from_mapping
from hiab_sim.machine.chains import Actuator, Chain, DecisionVariable, Linkage, Pivot
from hiab_sim.machine.description import Link, Machine
from hiab_sim.machine.kinematics.assembly import check_machine
from hiab_sim.machine.parts import IDENTITY, Matrix3, Pose, RigidBody, Vector3, rot_z
from hiab_sim.resources import Source, locate, shipped_names
from hiab_sim.yaml_fields import SafeLoader, duplicate_key, integer, mapping, number, parse_yaml, text, vector

#: Shipped machines' names (files in hiab_sim/presets/, :mod:`hiab_sim.resources` kind ``machine``).
PRESETS: tuple[str, ...] = tuple(shipped_names("machine"))

_TOP = {"name", "source", "gravity", "links", "chains", "tcp"}
_TOP_OPTIONAL = {"hydraulic", "workspace", "notes", "realistic_plant"}
_LINK = {"parent", "joint", "kind", "joint_frame", "joint_range", "bodies"}
_CHAIN = {"kind", "joint", "pivots", "actuator", "linkage", "variables"}
_ACTUATOR = {"stroke", "piston_offset", "rod_length", "emla", "hydraulic_cylinder", "cylinder_body", "rod_body"}
_ACTUATOR_OPTIONAL = {"body_scaling"}
_LINKAGE = {"rocker_length", "coupler_length", "pin_side", "rocker_body", "coupler_body"}
_BODY = {"mass", "com", "inertia", "inertia_zz"}
_VARIABLE = {"kind", "pivot", "bounds"}


class _UniqueKeyLoader(SafeLoader):  # type: ignore[misc,valid-type]
    """YAML safe loader that refuses a key given twice in one mapping (two links of one name)."""


def _unique_mapping(loader: _UniqueKeyLoader, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
    seen: set[Any] = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise ConfigError(f"line {key_node.start_mark.line + 1}: duplicate name {key!r} in one mapping")
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _unique_mapping)


def read_machine_yaml(source: Source) -> Any:
    """Parse a machine file; malformed YAML or a duplicate key raises :class:`ConfigError` naming the file."""
    text = source.read_text()
    try:
        return parse_yaml(text, _UniqueKeyLoader)
    except yaml.YAMLError as error:
        raise ConfigError(f"{source.label}: not valid YAML: {' '.join(str(error).split())}") from None
    except ConfigError as error:  # a duplicate key: name the file and the mapping that holds it
        found = duplicate_key(text)
        if found is None:
            raise ConfigError(f"{source.label}: {error}") from None
        line, path, key = found
        where = f" in {path}" if path else " at the top level"
        raise ConfigError(f"{source.label}: line {line}: duplicate name {key!r}{where}") from None


def load_machine(source: str | Path | Source = "xs031", *, check_assembly: bool = True) -> Machine:
    """Load and validate a machine (a shipped name or a path, :func:`hiab_sim.resources.locate`).

    ``check_assembly`` False skips the working-range assembly check.

    Raises:
        ConfigError: unknown machine or file, malformed YAML, unknown or missing keys.
        InvalidInputError: a value out of range, an unknown or duplicate name, or (with
            ``check_assembly``) the first assembly failure of :func:`check_machine`.

    """
    found = locate(source, "machine")
    return machine_from_dict(read_machine_yaml(found), origin=found.label, check_assembly=check_assembly, located=found)


def machine_from_dict(
    data: Any, origin: str = "machine", *, check_assembly: bool = True, located: Source | None = None
) -> Machine:
    """Build and validate a :class:`Machine` from a parsed YAML mapping.

    ``located``: the file it was read from, against which a relative ``realistic_plant`` path resolves.
    """
    top = mapping(data, origin, _TOP | _TOP_OPTIONAL, _TOP)
    if "notes" in top and not isinstance(top["notes"], Mapping | list | str):
        raise ConfigError("notes: expected text, a list or a mapping")
    links_node = mapping(top["links"], "links", None)
    links = _parents_first(tuple(_link(str(name), node) for name, node in links_node.items()))
    chains_node = mapping(top["chains"], "chains", None)
    chains = tuple(_chain(str(name), node) for name, node in chains_node.items())
    tcp = mapping(top["tcp"], "tcp", {"link", "r", "R", "angle"}, {"link", "r"})
    machine = Machine(
        name=text(top["name"], "name"),
        source=text(top["source"], "source"),
        gravity=number(top["gravity"], "gravity"),
        links=links,
        chains=chains,
        tcp_link=text(tcp["link"], "tcp.link"),
        tcp=_pose(tcp, "tcp"),
        hydraulic=_hydraulic(top["hydraulic"]) if "hydraulic" in top else None,
        workspace=_workspace(top["workspace"]) if "workspace" in top else None,
        realistic_plant=_plant(top["realistic_plant"], located) if "realistic_plant" in top else None,
    )
    for variable, value in zip(machine.decision_variables, machine.design_values(), strict=True):
        check_range(f"chains.{variable.chain}.variables.{variable.name}", value, variable.low, variable.high, "m")
    if check_assembly:
        failures = check_machine(machine)
        if failures:
            raise failures[0].error()
    return machine


def _plant(node: Any, located: Source | None) -> str:
    """``realistic_plant``: a shipped plant name as it is, a file as its absolute path (it must exist)."""
    try:
        found = locate(text(node, "realistic_plant"), "plant", located)
    except ConfigError as error:
        raise ConfigError(f"realistic_plant: {error}") from None
    return found.label if found.shipped else str(Path(str(found.file)).resolve())


def _parents_first(links: tuple[Link, ...]) -> tuple[Link, ...]:
    """The links reordered so every parent precedes its children (file order otherwise kept).

    Links whose parent is unknown or that form a cycle keep their place at the end, where
    :class:`Machine` names the offending ``parent``.
    """
    placed: list[Link] = []
    names: set[str] = set()
    pending = list(links)
    while pending:
        left = []
        for link in pending:  # one pass in file order: a file listed parents-first keeps its order
            if link.parent is None or link.parent in names:
                placed.append(link)
                names.add(link.name)
            else:
                left.append(link)
        if len(left) == len(pending):
            return (*placed, *left)
        pending = left
    return tuple(placed)


def _vec3(value: Any, where: str) -> Vector3:
    """(x, y) or (x, y, z) [m]; z defaults to 0."""
    if isinstance(value, list | tuple) and len(value) == 2:
        x, y = vector(value, where, 2)
        return (x, y, 0.0)
    x, y, z = vector(value, where, 3)
    return (x, y, z)


def _matrix(value: Any, where: str) -> Matrix3:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ConfigError(f"{where}: expected a 3x3 nested list, got {value!r}")
    rows = [vector(row, f"{where}[{i}]", 3) for i, row in enumerate(value)]
    return (
        (rows[0][0], rows[0][1], rows[0][2]),
        (rows[1][0], rows[1][1], rows[1][2]),
        (rows[2][0], rows[2][1], rows[2][2]),
    )


def _pose(node: Mapping[str, Any], where: str) -> Pose:
    if "R" in node and "angle" in node:
        raise ConfigError(f"{where}: give R or angle, not both")
    if "R" in node:
        rotation = _matrix(node["R"], f"{where}.R")
    elif "angle" in node:
        rotation = rot_z(number(node["angle"], f"{where}.angle"))
    else:
        rotation = IDENTITY
    try:
        return Pose(_vec3(node.get("r", [0.0, 0.0]), f"{where}.r"), rotation)
    except InvalidInputError as error:  # Pose names its own fields (r, R); say where it is
        raise InvalidInputError(f"{where}.{error.field}", error.value, error.allowed, error.unit) from None


def _range(value: Any, where: str) -> tuple[float, float]:
    low, high = vector(value, where, 2)
    return (low, high)


def _body(name: str, node: Any, where: str) -> RigidBody:
    body = mapping(node, where, _BODY, {"mass", "com"})
    if ("inertia" in body) == ("inertia_zz" in body):
        raise ConfigError(f"{where}: give exactly one of inertia (3x3) or inertia_zz (planar)")
    mass = number(body["mass"], f"{where}.mass")
    com = _vec3(body["com"], f"{where}.com")
    if "inertia" in body:
        inertia, planar = _matrix(body["inertia"], f"{where}.inertia"), False
    else:
        izz = number(body["inertia_zz"], f"{where}.inertia_zz")
        if izz <= 0.0:
            raise InvalidInputError(f"{where}.inertia_zz", izz, "must be > 0", "kg m^2")
        inertia, planar = ((0.5 * izz, 0.0, 0.0), (0.0, 0.5 * izz, 0.0), (0.0, 0.0, izz)), True
    try:
        return RigidBody(name, mass, com, inertia, planar)
    except InvalidInputError as error:  # RigidBody names fields after its name; say where it is
        field = error.field.split(".", 1)[-1]
        raise InvalidInputError(f"{where}.{field}", error.value, error.allowed, error.unit) from None


def _link(name: str, node: Any) -> Link:
    where = f"links.{name}"
    link = mapping(node, where, _LINK, set() if node is None or "parent" not in node else {"parent", "joint", "kind"})
    bodies = mapping(link.get("bodies", {}), f"{where}.bodies", None)
    parts = tuple(_body(str(b), bodies[b], f"{where}.bodies.{b}") for b in bodies)
    frame = mapping(link.get("joint_frame", {}), f"{where}.joint_frame", {"r", "R", "angle"}, set())
    parent = text(link["parent"], f"{where}.parent") if "parent" in link else None
    return Link(
        name=name,
        parent=parent,
        joint=text(link["joint"], f"{where}.joint") if "joint" in link else f"{name}_mount",
        joint_kind=text(link["kind"], f"{where}.kind") if "kind" in link else "fixed",
        joint_frame=_pose(frame, f"{where}.joint_frame"),
        joint_range=_range(link["joint_range"], f"{where}.joint_range") if "joint_range" in link else None,
        parts=parts,
    )


def _optional_body(node: Mapping[str, Any], key: str, where: str, chain: str) -> RigidBody | None:
    """A chain's own body (cylinder, rod, rocker, coupler), named ``<chain>_<part>``."""
    if key not in node or node[key] is None:
        return None
    return _body(f"{chain}_{key.removesuffix('_body')}", node[key], f"{where}.{key}")


def _optional_length(node: Mapping[str, Any], key: str, where: str) -> float | None:
    return number(node[key], f"{where}.{key}") if key in node else None


def _emla_name(value: Any, where: str) -> str:
    """An actuator's EMLA name: an identifier, as the EMLA file's ``actuators`` keys must be."""
    name = text(value, where)
    if not name.isidentifier():
        raise InvalidInputError(where, name, "must be an identifier (letters, digits, _): an EMLA file's actuator key")
    return name


def _chain(name: str, node: Any) -> Chain:
    where = f"chains.{name}"
    chain = mapping(node, where, _CHAIN, {"kind", "joint", "actuator"})
    act_where = f"{where}.actuator"
    act = mapping(chain["actuator"], act_where, _ACTUATOR | _ACTUATOR_OPTIONAL, {"stroke", "emla"})
    actuator = Actuator(
        stroke=number(act["stroke"], f"{act_where}.stroke"),
        piston_offset=_optional_length(act, "piston_offset", act_where),
        rod_length=_optional_length(act, "rod_length", act_where),
        emla=_emla_name(act["emla"], f"{act_where}.emla"),
        hydraulic_cylinder=text(act["hydraulic_cylinder"], f"{act_where}.hydraulic_cylinder")
        if "hydraulic_cylinder" in act
        else None,
        cylinder_body=_optional_body(act, "cylinder_body", act_where, name),
        rod_body=_optional_body(act, "rod_body", act_where, name),
        body_scaling=text(act.get("body_scaling", "slender"), f"{act_where}.body_scaling"),
    )
    pivots_node = mapping(chain.get("pivots", {}), f"{where}.pivots", None)
    pivots = []
    for role, p in pivots_node.items():
        pw = f"{where}.pivots.{role}"
        pnode = mapping(p, pw, {"link", "position"})
        pivots.append(Pivot(str(role), text(pnode["link"], f"{pw}.link"), _vec3(pnode["position"], f"{pw}.position")))
    linkage = None
    if "linkage" in chain:
        lw = f"{where}.linkage"
        ln = mapping(chain["linkage"], lw, _LINKAGE, {"rocker_length", "coupler_length", "pin_side"})
        linkage = Linkage(
            rocker_length=number(ln["rocker_length"], f"{lw}.rocker_length"),
            coupler_length=number(ln["coupler_length"], f"{lw}.coupler_length"),
            pin_side=integer(ln["pin_side"], f"{lw}.pin_side"),
            rocker_body=_optional_body(ln, "rocker_body", lw, name),
            coupler_body=_optional_body(ln, "coupler_body", lw, name),
        )
    variables_node = mapping(chain.get("variables", {}), f"{where}.variables", None)
    variables = []
    for vname, v in variables_node.items():
        vw = f"{where}.variables.{vname}"
        vnode = mapping(v, vw, _VARIABLE, {"kind", "bounds"})
        low, high = _range(vnode["bounds"], f"{vw}.bounds")
        pivot = text(vnode["pivot"], f"{vw}.pivot") if "pivot" in vnode else None
        variables.append(DecisionVariable(name, str(vname), text(vnode["kind"], f"{vw}.kind"), pivot, low, high))
    return Chain(
        name=name,
        kind=text(chain["kind"], f"{where}.kind"),
        joint=text(chain["joint"], f"{where}.joint"),
        actuator=actuator,
        pivots=tuple(pivots),
        linkage=linkage,
        variables=tuple(variables),
    )


def _hydraulic(node: Any) -> HydraulicSystem:
    top = mapping(node, "hydraulic", {"cylinders", "supply_pressure", "friction"}, {"cylinders", "supply_pressure"})
    cylinders_node = mapping(top["cylinders"], "hydraulic.cylinders", None)
    cylinders = tuple(
        cylinder_from_mapping(c, f"hydraulic.cylinders.{name}", str(name)) for name, c in cylinders_node.items()
    )
    return system_from_mapping(top, "hydraulic", cylinders)


def _workspace(node: Any) -> tuple[tuple[float, float], tuple[float, float]]:
    ws = mapping(node, "workspace", {"x", "y"})
    return (_range(ws["x"], "workspace.x"), _range(ws["y"], "workspace.y"))

"""The documented keys of every file format, built from the dataclasses and readers that own them.

Each format is a list of :class:`Key` rows: a *section* (a mapping whose keys are listed after it), a
*value*, or *free* (any name or dotted path). Where a reader builds a dataclass from a section
(:func:`hiab_sim.yaml_fields.section` and its kin), the rows come from that dataclass
(:func:`~hiab_sim.docs_site.dataclass_fields.field_rows`: its type, default, the docstring's
description and unit, the range its ``__post_init__`` checks); the keys a reader handles by hand are
written here once, next to the reader's name. ``tests/test_file_formats.py`` holds these rows to the keys
the loaders accept (:mod:`hiab_sim.docs_site.probe`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from hiab_sim.docs_site.dataclass_fields import field_rows

SOURCED = "number or {value, source}"


@dataclass(frozen=True)
class Key:
    """One documented key: dotted path (grammar of :mod:`hiab_sim.docs_site.probe`), kind and its facts."""

    path: str
    kind: str = "value"  # "value", "section" (a mapping of the keys below it) or "free" (any key)
    type: str = ""
    unit: str = ""
    default: str = ""
    allowed: str = ""
    description: str = ""


def section(path: str, description: str, default: str = "required") -> Key:
    """A mapping whose keys are documented by the rows below it."""
    return Key(path, "section", "mapping", default=default, description=description)


def free(path: str, description: str, type_: str = "") -> Key:
    """A mapping whose keys are names or dotted paths chosen by the user."""
    return Key(path, "free", type_, description=description)


def from_class(prefix: str, cls: type, skip: tuple[str, ...] = ("label",), **overrides: dict[str, str]) -> list[Key]:
    """The rows of dataclass ``cls``'s fields under ``prefix``; ``overrides`` replace facts per field."""
    out = []
    for name, facts in field_rows(cls, skip).items():
        row = {**facts, **overrides.get(name, {})}
        out.append(Key(f"{prefix}.{name}" if prefix else name, "value", **row))
    return out


def _sourced(keys: list[Key], required: bool = True) -> list[Key]:
    """Rows of a provenance-carrying section: each value a number or ``{value, source}``."""
    return [
        replace(k, type=SOURCED, default=k.default if not required or k.default != "required" else "required")
        for k in keys
    ]


def crane_keys() -> list[Key]:
    """The crane file (:func:`hiab_sim.crane.loader.crane_from_dict`), source frames and SI units."""
    chain = [
        Key("parent", type="text", description="Link the chain's cylinder base pivot sits on (e.g. `base`)."),
        Key(
            "cylinder_base_pivot",
            type="[number, number, number]",
            unit="m",
            description="Cylinder base pivot {Bc} at the default L, in the parent frame.",
        ),
        Key(
            "base_axis_angle",
            type="number",
            unit="rad",
            allowed="finite",
            description="Direction base pivot -> boom hinge in the parent frame.",
        ),
        Key(
            "joint_offset",
            type="number",
            unit="rad",
            allowed="finite",
            description="theta minus the boom's rotation relative to {Bc} (eq. `thetas`).",
        ),
        Key("L", type="number", unit="m", allowed="> 0", description="Base pivot -> boom hinge (seed's L)."),
        Key(
            "L1",
            type="number",
            unit="m",
            allowed="> 0",
            description="Boom hinge -> rod-end pivot (part of the boom, fixed).",
        ),
        Key("Lc", type="number", unit="m", allowed="> 0", description="Rod length (seed's Lc)."),
        Key("Lc0", type="number", unit="m", allowed="> 0", description="Piston offset (seed's Lc0); x0 = Lc0 + Lc."),
        Key("stroke", type="number", unit="m", allowed="> 0", description="Actuator stroke."),
        Key(
            "joint_range",
            type="[number, number]",
            unit="rad",
            allowed="low < high",
            description="Working range of theta the design must serve (const_j at its ends).",
        ),
    ]
    pose = [
        Key("r", type="[number, number, number]", unit="m", description="Position in the parent frame."),
        Key("R", type="3x3 nested list", allowed="a rotation matrix", description="Rotation parent -> frame."),
    ]
    cylinder = [
        Key("bore", type="number", unit="m", allowed="> 0", description="Piston diameter D."),
        Key("rod", type="number", unit="m", allowed="0 < rod < bore", description="Rod diameter d."),
        Key("stroke", type="number", unit="m", allowed="> 0", description="Stroke (reported, not a limit)."),
        Key(
            "pin_to_pin_at_zero",
            type="number",
            unit="m",
            default="none",
            description="Pin-to-pin length at zero stroke (read, not used by the model).",
        ),
        section(
            "counterbalance",
            "Counterbalance valve in the outlet of the load-holding chamber (hydraulic baselines at the battery).",
            default="none",
        ),
        Key("counterbalance.side", type="piston | rod", description="The chamber the valve holds."),
        Key("counterbalance.pilot_ratio", type="number", allowed="> 0", description="Pilot ratio R."),
        Key(
            "counterbalance.setting_pressure",
            type="number",
            unit="Pa",
            allowed="> 0",
            description="Setting p_set: opens when p_out + R p_pilot = p_set.",
        ),
        Key(
            "counterbalance.check_pressure",
            type="number",
            unit="Pa",
            allowed=">= 0",
            default="0",
            description="Cracking pressure of the free-flow check.",
        ),
    ]
    rows = [
        Key("name", type="text", description="Crane name, used in reports."),
        Key("source", type="text", description="Where the data comes from (citation)."),
        Key("gravity", type="number", unit="m/s^2", description="Gravitational acceleration, along -y of {W}."),
        section("chains", "The two closed chains (cylinder, rod, boom triangle)."),
    ]
    for name in ("lift", "tilt"):
        rows.append(section(f"chains.{name}", f"The {name} chain."))
        rows += [replace(k, path=f"chains.{name}.{k.path}") for k in chain]
    rows += [
        section("telescope", "The telescope: a prismatic joint xt2 along x of the cylinder frame {P22}."),
        Key("telescope.parent", type="text", description="Link the telescope cylinder is fixed to."),
        section("telescope.cylinder_frame", "{P22} in the parent link frame."),
        *[replace(k, path=f"telescope.cylinder_frame.{k.path}") for k in pose],
        Key(
            "telescope.rod_offset",
            type="number",
            unit="m",
            allowed="finite",
            description="{B52} at (rod_offset + xt2, 0, 0) in {P22}.",
        ),
        Key(
            "telescope.rod_length",
            type="number",
            unit="m",
            allowed="> 0",
            description="{B52} -> end-mass frame {P32} along x.",
        ),
        Key("telescope.stroke", type="number", unit="m", allowed="> 0", description="Telescope stroke."),
        Key(
            "telescope.joint_range",
            type="[number, number]",
            unit="m",
            allowed="within [0, stroke]",
            description="Working range of xt2.",
        ),
        section("tcp", "TCP frame in the end-mass frame."),
        *[replace(k, path=f"tcp.{k.path}") for k in pose],
        free("bodies", "Rigid bodies by name, each `{frame, mass, com, inertia}` in its source frame."),
        section("hydraulic_cylinders", "The cylinders the EMLAs replace (hydraulic baseline).", default="none"),
    ]
    for name in ("lift", "tilt", "telescope"):
        rows.append(section(f"hydraulic_cylinders.{name}", f"The {name} cylinder."))
        rows += [replace(k, path=f"hydraulic_cylinders.{name}.{k.path}") for k in cylinder]
    rows += [
        Key(
            "hydraulic_cylinders.supply_pressure",
            type="number",
            unit="Pa",
            allowed="> 0",
            description="System (relief) pressure p_s.",
        ),
        section("hydraulic_cylinders.friction", "Seal friction of every cylinder.", default="none"),
        Key(
            "hydraulic_cylinders.friction.coulomb",
            type="number",
            unit="N",
            default="0",
            allowed=">= 0",
            description="Coulomb seal friction F_c opposing the rod velocity.",
        ),
        Key(
            "hydraulic_cylinders.friction.viscous",
            type="number",
            unit="N s/m",
            default="0",
            allowed=">= 0",
            description="Viscous friction b.",
        ),
    ]
    return rows


def emla_keys() -> list[Key]:
    """The EMLA file (:func:`hiab_sim.emla.config.emla_set_from_mapping`); values may carry a provenance."""
    from hiab_sim.emla.battery import BatteryParams
    from hiab_sim.emla.brake import HoldingBrake
    from hiab_sim.emla.config import DriveStiffness, EmlaParams, PmsmParams, ScrewColumn
    from hiab_sim.emla.electrothermal import WindingResistance
    from hiab_sim.emla.losses import DriveLosses
    from hiab_sim.emla.thermal import ThermalParams

    pmsm = _sourced(from_class("", PmsmParams))
    actuator = [
        k
        for k in _sourced(
            from_class(
                "",
                EmlaParams,
                skip=("name", "motor", "losses", "thermal", "winding", "brake", "provenance", "screw", "stiffness"),
            )
        )
    ]
    screw = _sourced(from_class("", ScrewColumn))
    stiffness = _sourced(from_class("", DriveStiffness))
    thermal = _sourced(from_class("", ThermalParams))
    losses = _sourced(from_class("", DriveLosses), required=False)
    winding = _sourced(from_class("", WindingResistance))
    brake = _sourced(from_class("", HoldingBrake))
    rows = [
        section("pmsm", "The motor shared by every actuator (an actuator may override any key in its own `pmsm`)."),
        *[replace(k, path=f"pmsm.{k.path}") for k in pmsm],
        section("actuators", "One section per actuator (`lift`, `tilt`, `telescope`)."),
    ]
    for name in ("lift", "tilt", "telescope"):
        where = f"actuators.{name}"
        rows.append(section(where, f"The {name} EMLA: gearbox, screw, optional overrides."))
        rows += [replace(k, path=f"{where}.{k.path}") for k in actuator]
        rows.append(section(f"{where}.pmsm", "Overrides of the shared `pmsm` keys.", default="none"))
        rows += [replace(k, path=f"{where}.pmsm.{k.path}", default="shared") for k in pmsm]
        rows.append(section(f"{where}.thermal", "Overrides of the shared `thermal` keys.", default="none"))
        rows += [replace(k, path=f"{where}.thermal.{k.path}", default="shared") for k in thermal]
        rows.append(section(f"{where}.drive_losses", "Overrides of the shared `drive_losses` keys.", default="none"))
        rows += [replace(k, path=f"{where}.drive_losses.{k.path}", default="shared") for k in losses]
        for key, doc, keys in (
            ("winding_resistance", "Overrides of the shared `winding_resistance` keys.", winding),
            ("holding_brake", "Overrides of the shared `holding_brake` keys.", brake),
        ):
            rows.append(section(f"{where}.{key}", doc, default="none"))
            rows += [replace(k, path=f"{where}.{key}.{k.path}", default="shared") for k in keys]
        rows.append(section(f"{where}.screw", "Overrides of the shared `screw` keys.", default="none"))
        rows += [replace(k, path=f"{where}.screw.{k.path}", default="shared") for k in screw]
        rows.append(
            section(f"{where}.drive_stiffness", "Overrides of the shared `drive_stiffness` keys.", default="none")
        )
        rows += [replace(k, path=f"{where}.drive_stiffness.{k.path}", default="shared") for k in stiffness]
    rows += [
        section(
            "thermal",
            "Continuous torque and first-order winding model of every motor (thermal limits).",
            default="none",
        ),
        *[replace(k, path=f"thermal.{k.path}") for k in thermal],
        section(
            "drive_losses", "Optional transmission, inverter and brake losses; all off by default.", default="none"
        ),
        Key(
            "drive_losses.enabled",
            type="true/false",
            default="true",
            description="`false` keeps every loss off (the keys below are then ignored).",
        ),
        *[replace(k, path=f"drive_losses.{k.path}") for k in losses],
        section(
            "winding_resistance",
            "R_s(T) = R_s,ref (1 + alpha (T - T_ref)): hot windings (hiab_sim.emla.electrothermal).",
            default="none",
        ),
        *[replace(k, path=f"winding_resistance.{k.path}") for k in winding],
        section("holding_brake", "The holding brake on every motor shaft (hiab_sim.emla.hold).", default="none"),
        *[replace(k, path=f"holding_brake.{k.path}") for k in brake],
        section(
            "screw",
            "Every screw as a column under its push force (buckling rows and margins); none: no buckling check.",
            default="none",
        ),
        *[replace(k, path=f"screw.{k.path}") for k in screw],
        section(
            "drive_stiffness",
            "Axial stiffness of every drive train (natural frequencies); none: no frequency check.",
            default="none",
        ),
        *[replace(k, path=f"drive_stiffness.{k.path}") for k in stiffness],
        section("battery", "Shared DC bus and battery efficiencies (battery energy).", default="defaults"),
        *[replace(k, path=f"battery.{k.path}") for k in _sourced(from_class("", BatteryParams), required=False)],
    ]
    return rows


def _reference_keys(where: str) -> list[Key]:
    from hiab_sim.study.references.kinds import PickAndPlace

    spiral = [
        Key(
            "kind",
            type="text",
            default="spiral",
            allowed="one of `spiral`, `pick_and_place`, `csv`",
            description="The kind of reference.",
        ),
        Key("duration", type="number", unit="s", default="grid.duration", allowed="> 0", description="Duration."),
        Key(
            "centre_joints",
            type="[number, number]",
            unit="rad",
            default="none",
            description="Spiral centre as the TCP at (theta1, theta2) with xt2 = telescope_start (or centre_tcp).",
        ),
        Key("centre_tcp", type="[number, number]", unit="m", default="none", description="Spiral centre in {W}."),
        Key("start_radius", type="number", unit="m", description="Radius at the start."),
        Key("end_radius", type="number", unit="m", description="Radius at the end."),
        Key("turns", type="number", description="Turns (counter-clockwise)."),
        Key("start_angle", type="number", unit="rad", default="0", description="Start angle from +x of {W}."),
        Key("telescope_start", type="number", unit="m", description="xt2 at both ends (prescribed)."),
        Key(
            "telescope_amplitude",
            type="number",
            unit="m",
            default="0",
            description="xt2 goes out by this much at mid-motion and back.",
        ),
    ]
    pick = [Key("kind", type="text", allowed="`pick_and_place`", description="The kind of reference.")]
    pick += [replace(k, default="[1, 1]" if k.path == "dwell" else k.default) for k in from_class("", PickAndPlace)]
    csv = [
        Key("kind", type="text", allowed="`csv`", description="The kind of reference."),
        Key(
            "file",
            type="path",
            description="CSV `t, x, y[, xt2]` (TCP) or `t, theta1, theta2, xt2` (joints), "
            "SI units, a header row, `#` comments; relative to the study file.",
        ),
        Key(
            "telescope",
            type="number",
            unit="m",
            default="none",
            description="xt2 when the TCP file has no `xt2` column.",
        ),
        Key(
            "control_points",
            type="integer",
            default="by duration",
            allowed=">= 7",
            description="Control points of the least-squares B-spline fit.",
        ),
        Key(
            "fit_tolerance",
            type="number",
            unit="m",
            default="0.005",
            allowed="> 0",
            description="Largest distance of the fit from any sample.",
        ),
    ]
    needed = "one of `reference`, `tasks`" if where == "reference" else "required"
    rows = [section(f"{where}{{spiral}}", "A TCP spiral in the vertical plane (kind omitted or `spiral`).", needed)]
    rows += [replace(k, path=f"{where}{{spiral}}.{k.path.lstrip('.')}") for k in spiral]
    rows.append(section(f"{where}{{pick_and_place}}", "Rest to rest from `pick` to `place` over a clearance.", needed))
    rows += [replace(k, path=f"{where}{{pick_and_place}}.{k.path.lstrip('.')}") for k in pick]
    rows.append(section(f"{where}{{csv}}", "A sampled trajectory from a CSV file, fitted by a B-spline.", needed))
    rows += [replace(k, path=f"{where}{{csv}}.{k.path.lstrip('.')}") for k in csv]
    return rows


def _payload_keys(where: str) -> list[Key]:
    from hiab_sim.study.spec.payload import Payload

    rows = [
        section(where, "A number (constant mass [kg]) or a mapping: the mass held from pick to release.", default="0")
    ]
    rows += [replace(k, path=f"{where}.{k.path}") for k in from_class("", Payload)]
    return rows


def _structure_keys() -> list[Key]:
    """The study's ``structure`` section (:meth:`hiab_sim.structure.settings.StructureSettings.from_mapping`)."""
    from hiab_sim.structure.settings import StructureSettings

    rows = from_class("structure", StructureSettings, skip=("pin_load_limits_N",))
    return [
        section("structure", "Structural rows of the NLP: buckling, pin loads, natural frequency.", "none"),
        *rows,
        free(
            "structure.pin_load_limits",
            "Pin name (`<chain>.<pin>`, as `hiab-sim machine show` lists them) -> largest |F| [N] > 0; "
            "one row per pin and sample.",
            "number",
        ),
    ]


def study_keys() -> list[Key]:
    """The study file (:func:`hiab_sim.study.spec.study_file.study_from_dict`)."""
    from hiab_sim.study.nlp.objectives import OBJECTIVES
    from hiab_sim.study.spec.build import BuildSettings
    from hiab_sim.study.spec.energy import DutySettings
    from hiab_sim.study.spec.study_file import GridSettings, SolverSettings, SplineSettings, Tracking

    rows = [
        Key("name", type="text", default="the file's stem", description="Study name (result folder, reports)."),
        Key("crane", type="text", description="Crane preset name (`xs031`) or a crane file, relative to the study."),
        Key("emla", type="text", default="default", description="EMLA preset name or an EMLA file."),
        section(
            "initial_lengths",
            "Start of the optimisation (default: the crane's own lengths, moved into the bounds).",
            default="the crane's",
        ),
    ]
    for chain in ("lift", "tilt"):
        rows.append(section(f"initial_lengths.{chain}", f"The {chain} chain's start."))
        rows += [
            Key(
                f"initial_lengths.{chain}.{k}", type="number", unit="m", allowed="> 0, within the bounds", description=d
            )
            for k, d in (("L", "Base pivot -> boom hinge."), ("Lc0", "Piston offset."), ("Lc", "Rod length."))
        ]
    rows += [
        section("spline", "Joint-trajectory B-splines (eqs. `matrix_basis`..`matrix_basis_dd`).", "defaults"),
        *from_class("spline", SplineSettings),
    ]
    rows += [section("grid", "Collocation grid.", "defaults"), *from_class("grid", GridSettings)]
    rows += _reference_keys("reference")
    rows += _payload_keys("payload")
    rows += [
        Key(
            "tasks",
            kind="value",
            type="list",
            default="one of `reference`, `tasks`",
            description="Tasks of a duty mix (instead of `reference` and `payload`).",
        ),
        section("tasks[]", "One task."),
        Key("tasks[].name", type="text", description="Unique task name."),
        Key("tasks[].weight", type="number", allowed="> 0", description="Share of the work (e.g. cycles per hour)."),
        Key(
            "tasks[].control_points",
            type="integer",
            default="by duration",
            allowed=">= 7",
            description="The task's spline control points.",
        ),
        *_reference_keys("tasks[].reference"),
        *_payload_keys("tasks[].payload"),
    ]
    rows += [section("tracking", "Tolerance bands of const_b..const_d.", "defaults"), *from_class("tracking", Tracking)]
    rows += _structure_keys()
    rows += [
        section("bounds", "Box and path bounds of the NLP."),
        *[
            k
            for chain in ("lift", "tilt")
            for k in (
                section(f"bounds.{chain}", f"Bounds of the {chain} chain's Xi (const_g)."),
                Key(
                    f"bounds.{chain}.low",
                    type="[number, number, number]",
                    unit="m",
                    allowed="0 < low < up",
                    description="Lower bounds of L, Lc0, Lc.",
                ),
                Key(
                    f"bounds.{chain}.up",
                    type="[number, number, number]",
                    unit="m",
                    description="Upper bounds of L, Lc0, Lc.",
                ),
            )
        ],
        Key(
            "bounds.joint_velocity",
            type="[number, number, number]",
            unit="rad/s, rad/s, m/s",
            default="[0.6, 0.6, 0.5]",
            allowed="> 0",
            description="Joint-velocity limits (const_i).",
        ),
        Key(
            "bounds.triangle_margin_deg",
            type="number",
            unit="deg",
            default="10",
            allowed="[0, 60)",
            description="Smallest interior angle at the boom hinge and its supplement (const_k).",
        ),
        Key(
            "bounds.working_margin_deg",
            type="number",
            unit="deg",
            default="3",
            allowed="[0, 30]",
            description="With `working_range: reference`, the reference's joint range widened by this.",
        ),
        Key(
            "bounds.envelope_margin",
            type="number",
            default="0.02",
            allowed="[0, 0.5)",
            description="EMLA envelope margins held at the collocation points.",
        ),
        Key(
            "bounds.working_range",
            type="text",
            default="crane",
            allowed="one of `crane`, `reference`",
            description="`crane`: the design serves the crane's full joint range; `reference`: only the reference's.",
        ),
    ]
    rows += [section("solver", "Solver settings.", "defaults"), *from_class("solver", SolverSettings)]
    rows += [
        section("build", "Manufacturing tolerance and stroke margin.", "defaults"),
        *from_class("build", BuildSettings),
    ]
    rows += [
        section("mounting", "Mounting-space polygons of the base pivots and a pin clearance.", "none"),
        Key(
            "mounting.lift",
            type="list of [x, y]",
            unit="m",
            default="none",
            description="Convex polygon of the lift base pivot in {W}, counter-clockwise.",
        ),
        Key(
            "mounting.tilt",
            type="list of [x, y]",
            unit="m",
            default="none",
            description="Convex polygon of the tilt base pivot in {B11}.",
        ),
        Key(
            "mounting.clearance",
            type="number",
            unit="m",
            default="0.05",
            allowed="> 0",
            description="Centre-to-centre clearance from other pins and the swept boom.",
        ),
        Key(
            "mounting.samples",
            type="integer",
            default="(built in)",
            allowed=">= 2",
            description="Joint samples over the working range for the boom clearance.",
        ),
        Key(
            "objective",
            type="text",
            default="costf2",
            allowed="one of " + ", ".join(f"`{n}`" for n in OBJECTIVES),
            description="What the optimiser minimises: the seed's eq. `costf2` or the battery energy.",
        ),
        section("duty", "Rest between cycles: thermal rows and report (give exactly one key).", "none"),
        *from_class(
            "duty",
            DutySettings,
            rest_time={"unit": "s", "description": "Rest after each cycle."},
            cycles_per_hour={"unit": "1/h", "description": "Cycles per hour (rest = 3600/n - T)."},
        ),
        section("transmission", "Catalogue of (gear ratio, screw lead) options per actuator: co-design.", "none"),
    ]
    for name in ("lift", "tilt", "telescope"):
        rows += [
            Key(f"transmission.{name}", type="list", default="the EMLA file's", description=f"Options for {name}."),
            section(f"transmission.{name}[]", "One option."),
            Key(f"transmission.{name}[].gear_ratio", type="number", allowed="> 1", description="Gearbox ratio G."),
            Key(f"transmission.{name}[].screw_lead", type="number", unit="m", allowed="> 0", description="Screw lead."),
        ]
    return rows


def sweep_keys() -> list[Key]:
    """The sweep file (:func:`hiab_sim.sweep.spec.load_sweep`)."""
    return [
        Key("name", type="text", default="the file's stem", description="Sweep name."),
        Key("study", type="text", description="Shipped study name or a study path relative to the sweep file."),
        free("set", "Dotted paths into the study (or `emla.` into its EMLA file) set at every point.", "path: value"),
        free(
            "grid",
            "Full factorial over axes: `path: [values]`, or a zipped axis `{values?, path: [..], ...}`.",
            "path: list",
        ),
        section("sample", "A seeded Latin-hypercube sample instead of a grid.", "none"),
        Key("sample.points", type="integer", allowed=">= 1", description="Number of points."),
        Key("sample.seed", type="integer", default="0", description="Seed of `scipy.stats.qmc.LatinHypercube`."),
        free("sample.ranges", "`path: [low, high]` per sampled path.", "path: [number, number]"),
    ]


def cases_keys() -> list[Key]:
    """The validation cases file (:func:`hiab_sim.validation.load_cases`)."""
    from hiab_sim.validation import CaseSpec, Tolerances

    return [
        section("tolerances", "Pass thresholds of `hiab-sim validate`.", "defaults"),
        *from_class(
            "tolerances",
            Tolerances,
            force_relative={"description": "Force error over each actuator's peak |f| in the case."},
            velocity_absolute={"description": "Velocity error."},
            balance_relative={"description": "Power balance or virtual work of the analytic path, relative."},
        ),
        Key(
            "payload_force",
            type="[number, number, number]",
            unit="N",
            default="[0, -2452, 0]",
            description="TCP force in {W} of the payload cases (a 250 kg payload).",
        ),
        Key("cases", type="list", description="The cases."),
        section("cases[]", "One case."),
        *from_class(
            "cases[]",
            CaseSpec,
            skip=("payload",),
            name={"description": "Case name (`+payload` is appended for the payload copy)."},
            kind={"description": "What the case samples."},
            samples={"description": "Joint samples (`--samples` overrides)."},
            seed={"description": "Random seed."},
            length_sets={"description": "Random link-length sets (random_lengths)."},
            description={"description": "Shown in the table."},
        ),
        Key(
            "cases[].payload",
            type="text",
            default="both",
            allowed="one of `none`, `payload`, `both`",
            description="Run without, with, or without and with the payload force.",
        ),
    ]


#: Format name (:data:`hiab_sim.docs_site.formats.FORMATS`) -> its documented keys.
KEYS = {"crane": crane_keys, "emla": emla_keys, "study": study_keys, "sweep": sweep_keys, "cases": cases_keys}

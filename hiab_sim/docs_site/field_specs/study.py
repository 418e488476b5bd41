"""The study file's keys (:func:`hiab_sim.study.spec.study_file.study_from_dict`), from its settings dataclasses.

Two forms: a crane file's study (``crane:``) and a machine file's (``machine:``,
:func:`~hiab_sim.study.spec.study_file.machine_study_from_dict`); a row with a ``form`` belongs to that one only.
"""

from __future__ import annotations

from hiab_sim.crane.description import CHAIN_NAMES
from hiab_sim.crane.names import ACTUATOR_NAMES
from hiab_sim.docs_site.dataclass_fields import field_rows
from hiab_sim.docs_site.field_specs.references import control_points_key, payload_keys, reference_keys, soil_keys
from hiab_sim.docs_site.field_specs.rows import Key, free, from_class, in_form, names, number, section, section_of, text
from hiab_sim.machine.mounting_geometry import DEFAULT_CLEARANCE, DEFAULT_SAMPLES


def _structure_keys() -> list[Key]:
    """The study's ``structure`` section (:meth:`hiab_sim.structure.settings.StructureSettings.from_mapping`)."""
    from hiab_sim.structure.settings import StructureSettings

    rows = from_class("structure", StructureSettings, skip=("pin_load_limits_N",))
    return [
        section("structure", "Structural rows of the NLP: buckling, pin loads, natural frequency.", "none"),
        *rows,
        free(
            "structure.pin_load_limits",
            "Pin name -> largest |F| [N] > 0; one row per pin and sample. Crane form: `<chain>.<pin>` with "
            "pin `base_pivot`, `boom_hinge` or `rod_end`; machine form: a hinge by its joint's name or a loop pin "
            "`<chain>.<pin>` (the names of a result's `structure.pins`).",
            "number",
        ),
    ]


def _mounting_keys() -> list[Key]:
    """The study's ``mounting`` section (:meth:`hiab_sim.crane.mounting.MountingSpace.from_mapping`)."""
    return [
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
        number(
            "mounting.clearance",
            "m",
            "Centre-to-centre clearance from other pins and the swept boom (machine form: the swept link).",
            allowed="> 0",
            default=f"{DEFAULT_CLEARANCE:g}",
        ),
        Key(
            "mounting.samples",
            type="integer",
            default=str(DEFAULT_SAMPLES),
            allowed=">= 2",
            description="Joint samples over the working range for the boom (link) clearance.",
        ),
    ]


def _machine_mounting_keys() -> list[Key]:
    """A machine file's study's ``mounting`` (:meth:`hiab_sim.machine.mounting.MachineMountingSpace.from_mapping`)."""
    return [
        names(
            "mounting",
            "Actuator (a chain of the machine file) -> polygons of its pivots; a pin clearance and samples.",
            "mapping",
            form="machine",
            default="none",
        ),
        *in_form(
            "machine",
            [
                names(
                    "mounting.<actuator>",
                    "Pivot role of that chain (a triangle's `base`, `end`; a linkage's `base`, `rocker`, `coupler`) "
                    "-> polygon.",
                    "mapping",
                    default="none",
                ),
                Key(
                    "mounting.<actuator>.<pivot>",
                    type="list of [x, y]",
                    unit="m",
                    default="none",
                    description="Convex counter-clockwise polygon of a pivot a decision variable moves, in its "
                    "link's frame.",
                ),
                *_mounting_keys()[-2:],
            ],
        ),
    ]


def study_keys() -> list[Key]:
    """The study file (:func:`hiab_sim.study.spec.study_file.study_from_dict`)."""
    from hiab_sim.emla.hold import HOLD_MODES
    from hiab_sim.machine.loader import PRESETS as MACHINE_PRESETS
    from hiab_sim.study.nlp.objectives import OBJECTIVES
    from hiab_sim.study.spec.build import BuildSettings
    from hiab_sim.study.spec.energy import DutySettings
    from hiab_sim.study.spec.study_file import Bounds, GridSettings, SolverSettings, SplineSettings, Tracking

    bounds = field_rows(Bounds, ())

    rows = [
        text("name", "Study name (result folder, reports).", default="the file's stem"),
        text("crane", "Crane preset name (`xs031`) or a crane file, relative to the study.", form="crane"),
        text(
            "machine",
            "Shipped machine name or a machine file, relative to the study.",
            allowed="one of " + ", ".join(f"`{n}`" for n in MACHINE_PRESETS) + ", or a path",
            form="machine",
        ),
        Key(
            "tracked",
            type="list of text",
            default="`tcp_angle` per joint beyond two",
            allowed="joint names or `tcp_angle`",
            description="The tracked coordinates beyond the TCP's x, y (one per joint beyond two): "
            "the reference's further columns, held within the tracking bands.",
            form="machine",
        ),
        text(
            "emla",
            "EMLA preset name or an EMLA file; its actuator names must be the machine's actuators.",
            default="`default` (crane form); required (machine form)",
        ),
        section(
            "initial_lengths",
            "Start of the optimisation (default: the crane's own lengths, moved into the bounds).",
            default="the crane's",
        ),
    ]
    start = [
        number(k, "m", d, allowed="> 0, within the bounds")
        for k, d in (("L", "Base pivot -> boom hinge."), ("Lc0", "Piston offset."), ("Lc", "Rod length."))
    ]
    for chain in CHAIN_NAMES:
        rows += section_of(f"initial_lengths.{chain}", f"The {chain} chain's start.", start)
    rows = [*rows[:5], *in_form("crane", rows[5:])]  # the crane's initial lengths; the machine's below
    rows.append(
        names(
            "initial_lengths",
            "Decision variable `chain.variable` (as `hiab-sim machine show` lists them) -> start value "
            "[the variable's unit], within the machine file's bounds.",
            "mapping",
            form="machine",
            default="the machine file's values",
        )
    )
    per_duration = (
        "N, control points per joint over `grid.duration`; a task of another duration (a `csv` or "
        "`pick_and_place` reference, or a spiral with its own `duration`) gets N x its duration / `grid.duration`, "
        "rounded, at least degree + 2, unless it sets `tasks[].control_points` (seed: 22)."
    )
    rows += [
        section("spline", "Joint-trajectory B-splines (eqs. `matrix_basis`..`matrix_basis_dd`).", "defaults"),
        *from_class("spline", SplineSettings, control_points={"description": per_duration}),
    ]
    grid_duration = {
        "description": "The span [s] that `intervals` and `spline.control_points` are given over: the "
        "collocation step is `duration / intervals` and the spline has `spline.control_points` per `duration`. "
        "It is a task's duration only for a `spiral` without its own `duration`; a `csv` task lasts its "
        "file's time span (first to last row) and a `pick_and_place` task its dwells and move, each on its "
        "own grid at a step of at most this one. Keep it equal to a single task's duration to get exactly "
        "`intervals` and `spline.control_points`: a 10 s CSV with `duration: 5` gets twice both."
    }
    grid_intervals = {
        "description": "M, collocation intervals over `duration` (M + 1 points); a task of another duration "
        "gets ceil(its duration / step) intervals, a step of at most `duration / M`."
    }
    rows += [
        section("grid", "Collocation grid.", "defaults"),
        *from_class("grid", GridSettings, duration=grid_duration, intervals=grid_intervals),
    ]
    rows += reference_keys("reference")
    rows += payload_keys("payload")
    rows += [
        Key(
            "tasks",
            kind="value",
            type="list",
            default="one of `reference`, `tasks`",
            description="Tasks of a duty mix (instead of `reference` and `payload`).",
        ),
        section("tasks[]", "One task."),
        text("tasks[].name", "Unique task name."),
        number("tasks[].weight", "", "Share of the work (e.g. cycles per hour).", allowed="> 0"),
        control_points_key("tasks[].control_points", "The task's spline control points."),
        *reference_keys("tasks[].reference"),
        *payload_keys("tasks[].payload"),
        *soil_keys("tasks[].soil"),
    ]
    rows += [section("tracking", "Tolerance bands of const_b..const_d.", "defaults"), *from_class("tracking", Tracking)]
    rows += _structure_keys()
    chain_bounds = [
        Key(
            "low",
            type="[number, number, number]",
            unit="m",
            allowed="0 < low < up",
            description="Lower bounds of L, Lc0, Lc.",
        ),
        Key("up", type="[number, number, number]", unit="m", description="Upper bounds of L, Lc0, Lc."),
    ]
    rows += [
        section("bounds", "Box and path bounds of the NLP (a machine file declares its decision variables' own)."),
        *in_form(
            "crane",
            [
                k
                for chain in CHAIN_NAMES
                for k in section_of(f"bounds.{chain}", f"Bounds of the {chain} chain's Xi (const_g).", chain_bounds)
            ],
        ),
        Key(
            "bounds.joint_velocity",
            type="[number, number, number]",
            unit="rad/s, rad/s, m/s",
            default=bounds["joint_velocity"]["default"],
            allowed="> 0",
            description="Joint-velocity limits |dtheta1|, |dtheta2|, |dxt2| (const_i).",
            form="crane",
        ),
        Key(
            "bounds.joint_velocity",
            type="list of number, one per joint",
            unit="rad/s or m/s (the joint's)",
            allowed="> 0",
            description="Joint-velocity limits in the machine's joint order (const_i).",
            form="machine",
        ),
        number(
            "bounds.triangle_margin_deg",
            "deg",
            "Smallest interior angle at the boom hinge and its supplement (const_k).",
            allowed="[0, 60)",
            default="10",
        ),
        number(
            "bounds.working_margin_deg",
            "deg",
            "With `working_range: reference`, the reference's joint range widened by this.",
            allowed="[0, 30]",
            default="3",
        ),
        number(
            "bounds.envelope_margin",
            "",
            "EMLA envelope margins held at the collocation points.",
            allowed="[0, 0.5)",
            default="0.02",
        ),
        text(
            "bounds.working_range",
            "`crane` or `machine`: the design serves the machine's full joint range (the crane's, or "
            "each joint's working range in the machine file); `reference`: only the reference's. With `crane` "
            "or `machine` the inverse dynamics takes each triangle or linkage chain's joint (the crane's lift and "
            "tilt) only within that range narrowed by 0.02 rad at both ends (`ID_SLACK` in "
            "`hiab_sim/study/nlp/task_setup.py`), so that the line search's trial points stay evaluable: a "
            "reference that brings such a joint within 0.02 rad of its range's end is refused when the optimiser "
            "starts, naming the task, its file, the time and the joint (a `direct` chain's joint is not narrowed).",
            default=bounds["working_range"]["default"],
            allowed=bounds["working_range"]["allowed"],
        ),
    ]
    rows += [
        section("solver", "Solver settings.", "defaults"),
        *from_class(
            "solver", SolverSettings, joint_derivatives={"default": "analytic on a machine file, path on a crane file"}
        ),
    ]
    rows += [
        section("build", "Manufacturing tolerance and stroke margin.", "defaults"),
        *from_class("build", BuildSettings),
    ]
    rows += in_form("crane", _mounting_keys()) + _machine_mounting_keys()
    rows += [
        text(
            "objective",
            "What the optimiser minimises: the seed's eq. `costf2` or the battery energy.",
            default="costf2",
            allowed="one of " + ", ".join(f"`{n}`" for n in OBJECTIVES),
        ),
        section(
            "duty",
            "Rest between cycles: thermal rows and report (exactly one of rest_time, cycles_per_hour, rest_ratio).",
            "none",
        ),
        *from_class(
            "duty",
            DutySettings,
            rest_time={"unit": "s", "description": "Rest after each cycle."},
            cycles_per_hour={"unit": "1/h", "description": "Cycles per hour (rest = 3600/n - T)."},
            rest_ratio={"description": "Rest as a share of each task's cycle time T (rest = r T)."},
            hold={
                "allowed": "one of " + ", ".join(f"`{m}`" for m in (*HOLD_MODES, "none")),
                "default": "`brake` if every EMLA has brake data",
                "description": "What carries the machine during the rest.",
            },
        ),
        *in_form(
            "crane",
            [section("transmission", "Catalogue of (gear ratio, screw lead) options per actuator: co-design.", "none")],
        ),
        names(
            "transmission",
            "Actuator (a chain of the machine file, by name) -> its (gear ratio, screw lead) options: co-design.",
            "mapping",
            form="machine",
            default="none",
        ),
    ]
    for name, form, description in (
        *((name, "crane", f"Options for {name}.") for name in ACTUATOR_NAMES),
        ("<actuator>", "machine", "Options for one actuator (a chain of the machine file, by its name)."),
    ):
        rows += in_form(
            form,
            [
                Key(f"transmission.{name}", type="list", default="the EMLA file's", description=description),
                section(f"transmission.{name}[]", "One option."),
                number(f"transmission.{name}[].gear_ratio", "", "Gearbox ratio G.", allowed="> 1"),
                number(f"transmission.{name}[].screw_lead", "m", "Screw lead.", allowed="> 0"),
            ],
        )
    return rows

"""The keys of a study's reference trajectory and payload, at top level or per task of a duty mix."""

from __future__ import annotations

from dataclasses import replace

from hiab_sim.docs_site.field_specs.rows import Key, from_class, number, section, section_of, text


def control_points_key(path: str, description: str) -> Key:
    """The control points of a B-spline whose count follows from its duration unless given."""
    return Key(path, type="integer", default="by duration", allowed=">= 7", description=description)


def _kind(allowed: str, default: str = "") -> Key:
    """A reference section's ``kind`` key."""
    return text("kind", "The kind of reference.", default=default, allowed=allowed)


def reference_keys(where: str) -> list[Key]:
    """The reference sections at ``where`` (``reference`` or ``tasks[].reference``), one per kind."""
    from hiab_sim.study.references.kinds import PickAndPlace

    spiral = [
        _kind("one of `spiral`, `pick_and_place`, `csv`", default="spiral"),
        number("duration", "s", "Duration.", allowed="> 0", default="grid.duration"),
        Key(
            "centre_joints",
            type="[number, number]",
            unit="rad",
            default="none",
            description="Spiral centre as the TCP at (theta1, theta2) with xt2 = telescope_start (or centre_tcp).",
        ),
        Key("centre_tcp", type="[number, number]", unit="m", default="none", description="Spiral centre in {W}."),
        number("start_radius", "m", "Radius at the start."),
        number("end_radius", "m", "Radius at the end."),
        number("turns", "", "Turns (counter-clockwise)."),
        number("start_angle", "rad", "Start angle from +x of {W}.", default="0"),
        number("telescope_start", "m", "xt2 at both ends (prescribed)."),
        number("telescope_amplitude", "m", "xt2 goes out by this much at mid-motion and back.", default="0"),
    ]
    pick = [_kind("`pick_and_place`")]
    pick += [replace(k, default="[1, 1]" if k.path == "dwell" else k.default) for k in from_class("", PickAndPlace)]
    csv = [
        _kind("`csv`"),
        Key(
            "file",
            type="path",
            description="CSV in the machine's columns: `t, x, y` and each further tracked coordinate by name "
            "(TCP form: the crane's `xt2`, a machine file's `tracked`, e.g. `tcp_angle`) or `t` and every joint "
            "by name (joint form: the crane's `theta1, theta2, xt2`); SI units, a header row, `#` comments; "
            "relative to the study file.",
        ),
        number(
            "telescope",
            "m (the coordinate's)",
            "The further tracked coordinate (the crane's xt2) when the TCP file has no column for it.",
            default="none",
        ),
        control_points_key("control_points", "Control points of the least-squares B-spline fit."),
        number("fit_tolerance", "m", "Largest distance of the fit from any sample.", allowed="> 0", default="0.005"),
    ]
    needed = "one of `reference`, `tasks`" if where == "reference" else "required"
    machine = " A machine file's study: only where its third tracked coordinate is a joint (else `csv`)."
    spiral_text = "A TCP spiral in the vertical plane (kind omitted or `spiral`)."
    return [
        *section_of(f"{where}{{spiral}}", spiral_text + machine, spiral, needed),
        *section_of(
            f"{where}{{pick_and_place}}",
            "Rest to rest from `pick` to `place` over a clearance." + machine,
            pick,
            needed,
        ),
        *section_of(f"{where}{{csv}}", "A sampled trajectory from a CSV file, fitted by a B-spline.", csv, needed),
    ]


def payload_keys(where: str) -> list[Key]:
    """The payload at ``where`` (``payload`` or ``tasks[].payload``): a number or the ``Payload`` mapping."""
    from hiab_sim.study.spec.payload import Payload

    text = "A number (constant mass [kg]) or a mapping: the mass held from pick to release."
    return section_of(where, text, from_class("", Payload), default="0")


def soil_keys(where: str) -> list[Key]:
    """A task's soil contact at ``where`` (:meth:`hiab_sim.study.spec.soil_contact.SoilContact.from_mapping`)."""
    from hiab_sim.machine.dynamics.soil_file import SOILS
    from hiab_sim.study.spec.soil_contact import ATTITUDE, SoilContact

    facts = from_class("", SoilContact, skip=("source", "soil"))
    rows = {k.path: k for k in facts}
    return [
        section(
            where,
            "The soil the tool tip (the TCP) cuts along the reference: its cutting force (the fundamental "
            f"earthmoving equation) on the TCP; needs `{ATTITUDE}` among the machine's `tracked`.",
            default="none",
        ),
        text(
            f"{where}.soil",
            "A shipped soil or a soil file (see Soil file below); a path is read from the working folder, "
            "not next to the study.",
            allowed="one of " + ", ".join(f"`{n}`" for n in SOILS) + ", or a soil file",
        ),
        replace(
            rows["ground"],
            path=f"{where}.ground",
            unit="m",
            description="Height of the horizontal ground surface in the world frame.",
        ),
        replace(rows["width"], path=f"{where}.width", unit="m", description="The bucket's cutting-edge width."),
    ]

"""The EMLA file's keys (:func:`hiab_sim.emla.config.emla_set_from_mapping`), from the EMLA dataclasses.

Every value may carry its provenance (``{value, source}``); the actuators are a mapping of any names (a
study checks them against its machine's actuators), each may override any shared section.
"""

from __future__ import annotations

from dataclasses import replace

from hiab_sim.docs_site.field_specs.rows import Key, free, from_class, section, sourced


def emla_keys() -> list[Key]:
    """The EMLA file (:func:`hiab_sim.emla.config.emla_set_from_mapping`); values may carry a provenance."""
    from hiab_sim.emla.battery import BatteryParams
    from hiab_sim.emla.brake import HoldingBrake
    from hiab_sim.emla.config import DriveStiffness, EmlaParams, PmsmParams, ScrewColumn
    from hiab_sim.emla.electrothermal import WindingResistance
    from hiab_sim.emla.losses import DriveLosses
    from hiab_sim.emla.thermal import ThermalParams

    pmsm = sourced(from_class("", PmsmParams))
    actuator = [
        k
        for k in sourced(
            from_class(
                "",
                EmlaParams,
                skip=("name", "motor", "losses", "thermal", "winding", "brake", "provenance", "screw", "stiffness"),
            )
        )
    ]
    screw = sourced(from_class("", ScrewColumn))
    stiffness = sourced(from_class("", DriveStiffness))
    thermal = sourced(from_class("", ThermalParams))
    losses = sourced(from_class("", DriveLosses), required=False)
    winding = sourced(from_class("", WindingResistance))
    brake = sourced(from_class("", HoldingBrake))
    rows = [
        section("pmsm", "The motor shared by every actuator (an actuator may override any key in its own `pmsm`)."),
        *[replace(k, path=f"pmsm.{k.path}") for k in pmsm],
        free(
            "actuators",
            "Actuator name (an identifier) -> actuator, at least one. A study checks the names against its "
            "machine's actuators: a crane file's `lift`, `tilt`, `telescope`; a machine file's `actuators`.",
            "mapping",
        ),
    ]
    where = "actuators.<actuator>"
    rows.append(section(where, "One EMLA: gearbox, screw, optional overrides of the shared sections."))
    rows += [replace(k, path=f"{where}.{k.path}") for k in actuator]
    rows.append(section(f"{where}.pmsm", "Overrides of the shared `pmsm` keys.", default="none"))
    rows += [replace(k, path=f"{where}.pmsm.{k.path}", default="shared") for k in pmsm]
    for key, keys in (
        ("thermal", thermal),
        ("drive_losses", losses),
        ("winding_resistance", winding),
        ("holding_brake", brake),
        ("screw", screw),
        ("drive_stiffness", stiffness),
    ):
        rows.append(section(f"{where}.{key}", f"Overrides of the shared `{key}` keys.", default="none"))
        rows += [replace(k, path=f"{where}.{key}.{k.path}", default="shared") for k in keys]
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
        *[replace(k, path=f"battery.{k.path}") for k in sourced(from_class("", BatteryParams), required=False)],
    ]
    return rows

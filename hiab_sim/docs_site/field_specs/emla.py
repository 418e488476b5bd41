"""The EMLA file's keys (:func:`hiab_sim.emla.config.emla_set_from_mapping`), from the EMLA dataclasses.

Every value may carry its provenance (``{value, source}``); the actuators are a mapping of any names (a
study checks them against its machine's actuators), each may override any shared section.
"""

from __future__ import annotations

from hiab_sim.docs_site.field_specs.rows import Key, free, from_class, section_of, sourced


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
        *section_of(
            "pmsm", "The motor shared by every actuator (an actuator may override any key in its own `pmsm`).", pmsm
        ),
        free(
            "actuators",
            "Actuator name (an identifier) -> actuator, at least one. A study checks the names against its "
            "machine's actuators: a crane file's `lift`, `tilt`, `telescope`; a machine file's `actuators`.",
            "mapping",
        ),
    ]
    where = "actuators.<actuator>"
    rows += section_of(where, "One EMLA: gearbox, screw, optional overrides of the shared sections.", actuator)
    for key, keys in (
        ("pmsm", pmsm),
        ("thermal", thermal),
        ("drive_losses", losses),
        ("winding_resistance", winding),
        ("holding_brake", brake),
        ("screw", screw),
        ("drive_stiffness", stiffness),
    ):
        rows += section_of(
            f"{where}.{key}", f"Overrides of the shared `{key}` keys.", keys, "none", keys_default="shared"
        )
    enabled = Key(
        "enabled",
        type="true/false",
        default="true",
        description="`false` keeps every loss off (the keys below are then ignored).",
    )
    shared = (
        ("thermal", "Continuous torque and first-order winding model of every motor (thermal limits).", thermal),
        ("drive_losses", "Optional transmission, inverter and brake losses; all off by default.", [enabled, *losses]),
        (
            "winding_resistance",
            "R_s(T) = R_s,ref (1 + alpha (T - T_ref)): hot windings (hiab_sim.emla.electrothermal).",
            winding,
        ),
        ("holding_brake", "The holding brake on every motor shaft (hiab_sim.emla.hold).", brake),
        (
            "screw",
            "Every screw as a column under its push force (buckling rows and margins); none: no buckling check.",
            screw,
        ),
        (
            "drive_stiffness",
            "Axial stiffness of every drive train (natural frequencies); none: no frequency check.",
            stiffness,
        ),
    )
    for key, description, keys in shared:
        rows += section_of(key, description, keys, "none")
    battery = sourced(from_class("", BatteryParams), required=False)
    rows += section_of("battery", "Shared DC bus and battery efficiencies (battery energy).", battery, "defaults")
    return rows

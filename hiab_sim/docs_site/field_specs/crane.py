"""The crane file's keys (:func:`hiab_sim.crane.loader.crane_from_dict`): the source's frames, SI units.

The crane reader handles its keys by hand (no dataclass per section), so each row is written here once.
"""

from __future__ import annotations

from hiab_sim.docs_site.field_specs.rows import Key, free, section, section_of


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
        *section_of(
            "counterbalance",
            "Counterbalance valve in the outlet of the load-holding chamber (hydraulic baselines at the battery).",
            [
                Key("side", type="piston | rod", description="The chamber the valve holds."),
                Key("pilot_ratio", type="number", allowed="> 0", description="Pilot ratio R."),
                Key(
                    "setting_pressure",
                    type="number",
                    unit="Pa",
                    allowed="> 0",
                    description="Setting p_set: opens when p_out + R p_pilot = p_set.",
                ),
                Key(
                    "check_pressure",
                    type="number",
                    unit="Pa",
                    allowed=">= 0",
                    default="0",
                    description="Cracking pressure of the free-flow check.",
                ),
            ],
            default="none",
        ),
    ]
    rows = [
        Key("name", type="text", description="Crane name, used in reports."),
        Key("source", type="text", description="Where the data comes from (citation)."),
        Key("gravity", type="number", unit="m/s^2", description="Gravitational acceleration, along -y of {W}."),
        section("chains", "The two closed chains (cylinder, rod, boom triangle)."),
    ]
    for name in ("lift", "tilt"):
        rows += section_of(f"chains.{name}", f"The {name} chain.", chain)
    rows += [
        section("telescope", "The telescope: a prismatic joint xt2 along x of the cylinder frame {P22}."),
        Key("telescope.parent", type="text", description="Link the telescope cylinder is fixed to."),
        *section_of("telescope.cylinder_frame", "{P22} in the parent link frame.", pose),
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
        *section_of("tcp", "TCP frame in the end-mass frame.", pose),
        free("bodies", "Rigid bodies by name, each `{frame, mass, com, inertia}` in its source frame."),
        section("hydraulic_cylinders", "The cylinders the EMLAs replace (hydraulic baseline).", default="none"),
    ]
    for name in ("lift", "tilt", "telescope"):
        rows += section_of(f"hydraulic_cylinders.{name}", f"The {name} cylinder.", cylinder)
    rows += [
        Key(
            "hydraulic_cylinders.supply_pressure",
            type="number",
            unit="Pa",
            allowed="> 0",
            description="System (relief) pressure p_s.",
        ),
        *section_of(
            "hydraulic_cylinders.friction",
            "Seal friction of every cylinder.",
            [
                Key(
                    "coulomb",
                    type="number",
                    unit="N",
                    default="0",
                    allowed=">= 0",
                    description="Coulomb seal friction F_c opposing the rod velocity.",
                ),
                Key(
                    "viscous",
                    type="number",
                    unit="N s/m",
                    default="0",
                    allowed=">= 0",
                    description="Viscous friction b.",
                ),
            ],
            default="none",
        ),
    ]
    return rows

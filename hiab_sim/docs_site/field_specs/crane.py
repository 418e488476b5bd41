"""The crane file's keys (:func:`hiab_sim.crane.loader.crane_from_dict`): the source's frames, SI units.

The crane reader handles its keys by hand (no dataclass per section), so each row is written here once.
"""

from __future__ import annotations

from hiab_sim.crane.names import ACTUATOR_NAMES, CHAIN_NAMES, TELESCOPE
from hiab_sim.docs_site.field_specs.rows import Key, free, interval, number, section, section_of, text


def crane_keys() -> list[Key]:
    """The crane file (:func:`hiab_sim.crane.loader.crane_from_dict`), source frames and SI units."""
    chain = [
        text("parent", "Link the chain's cylinder base pivot sits on (e.g. `base`)."),
        Key(
            "cylinder_base_pivot",
            type="[number, number, number]",
            unit="m",
            description="Cylinder base pivot {Bc} at the default L, in the parent frame.",
        ),
        number("base_axis_angle", "rad", "Direction base pivot -> boom hinge in the parent frame.", allowed="finite"),
        number(
            "joint_offset", "rad", "theta minus the boom's rotation relative to {Bc} (eq. `thetas`).", allowed="finite"
        ),
        number("L", "m", "Base pivot -> boom hinge (seed's L).", allowed="> 0"),
        number("L1", "m", "Boom hinge -> rod-end pivot (part of the boom, fixed).", allowed="> 0"),
        number("Lc", "m", "Rod length (seed's Lc).", allowed="> 0"),
        number("Lc0", "m", "Piston offset (seed's Lc0); x0 = Lc0 + Lc.", allowed="> 0"),
        number("stroke", "m", "Actuator stroke.", allowed="> 0"),
        interval(
            "joint_range",
            "rad",
            "Working range of theta the design must serve (const_j at its ends).",
            allowed="low < high",
        ),
    ]
    pose = [
        Key("r", type="[number, number, number]", unit="m", description="Position in the parent frame."),
        Key("R", type="3x3 nested list", allowed="a rotation matrix", description="Rotation parent -> frame."),
    ]
    cylinder = [
        number("bore", "m", "Piston diameter D.", allowed="> 0"),
        number("rod", "m", "Rod diameter d.", allowed="0 < rod < bore"),
        number("stroke", "m", "Stroke (reported, not a limit).", allowed="> 0"),
        number(
            "pin_to_pin_at_zero", "m", "Pin-to-pin length at zero stroke (read, not used by the model).", default="none"
        ),
        *section_of(
            "counterbalance",
            "Counterbalance valve in the outlet of the load-holding chamber (hydraulic baselines at the battery).",
            [
                Key("side", type="piston | rod", description="The chamber the valve holds."),
                number("pilot_ratio", "", "Pilot ratio R.", allowed="> 0"),
                number("setting_pressure", "Pa", "Setting p_set: opens when p_out + R p_pilot = p_set.", allowed="> 0"),
                number(
                    "check_pressure", "Pa", "Cracking pressure of the free-flow check.", allowed=">= 0", default="0"
                ),
            ],
            default="none",
        ),
    ]
    rows = [
        text("name", "Crane name, used in reports."),
        text("source", "Where the data comes from (citation)."),
        number("gravity", "m/s^2", "Gravitational acceleration, along -y of {W}."),
        section("chains", "The two closed chains (cylinder, rod, boom triangle)."),
    ]
    for name in CHAIN_NAMES:
        rows += section_of(f"chains.{name}", f"The {name} chain.", chain)
    rows += [
        section(TELESCOPE, "The telescope: a prismatic joint xt2 along x of the cylinder frame {P22}."),
        text("telescope.parent", "Link the telescope cylinder is fixed to."),
        *section_of("telescope.cylinder_frame", "{P22} in the parent link frame.", pose),
        number("telescope.rod_offset", "m", "{B52} at (rod_offset + xt2, 0, 0) in {P22}.", allowed="finite"),
        number("telescope.rod_length", "m", "{B52} -> end-mass frame {P32} along x.", allowed="> 0"),
        number("telescope.stroke", "m", "Telescope stroke.", allowed="> 0"),
        interval("telescope.joint_range", "m", "Working range of xt2.", allowed="within [0, stroke]"),
        *section_of("tcp", "TCP frame in the end-mass frame.", pose),
        free("bodies", "Rigid bodies by name, each `{frame, mass, com, inertia}` in its source frame."),
        section("hydraulic_cylinders", "The cylinders the EMLAs replace (hydraulic baseline).", default="none"),
    ]
    for name in ACTUATOR_NAMES:
        rows += section_of(f"hydraulic_cylinders.{name}", f"The {name} cylinder.", cylinder)
    rows += [
        number("hydraulic_cylinders.supply_pressure", "Pa", "System (relief) pressure p_s.", allowed="> 0"),
        *section_of(
            "hydraulic_cylinders.friction",
            "Seal friction of every cylinder.",
            [
                number(
                    "coulomb", "N", "Coulomb seal friction F_c opposing the rod velocity.", allowed=">= 0", default="0"
                ),
                number("viscous", "N s/m", "Viscous friction b.", allowed=">= 0", default="0"),
            ],
            default="none",
        ),
    ]
    return rows

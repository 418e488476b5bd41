"""``hiab-sim machine show|check``: print and draw a machine description, or check that it assembles.

``show FILE|NAME`` prints links, chains, strokes, usable and reachable ranges, masses and decision
variables, and writes a labelled PNG drawing (``--figure``, default ``<name>_machine.png``).
``check FILE|NAME`` assembles every chain over its working range and prints one line per failure
(a stroke that does not cover the range, a chain passing its toggle, a loop that does not close,
a TCP outside the declared workspace); it exits 2 when anything fails.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from hiab_sim.machine.description import Machine
from hiab_sim.machine.kinematics.assembly import check_machine, reachable_joint_range, usable_stroke
from hiab_sim.machine.kinematics.closure import joint_to_stroke
from hiab_sim.machine.loader import load_machine


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "machine",
        help="show or check a machine description",
        description=(
            "Work with a machine description (links, closed chains of actuators, tool point): print it and draw "
            "it labelled, or assemble every chain over its working range and report what fails."
        ),
    )
    actions = parser.add_subparsers(dest="machine_command", metavar="ACTION", required=True)
    show = actions.add_parser("show", help="print the machine and write a labelled drawing (PNG)")
    show.add_argument("machine", help="shipped machine name (xs031, exact) or a machine YAML file")
    show.add_argument(
        "--figure", type=Path, help="PNG to write (default: <name>_machine.png; <name>.png if it ends in 'machine')"
    )
    show.add_argument("--no-figure", action="store_true", help="print only")
    show.set_defaults(run=run_show)
    check = actions.add_parser("check", help="assemble every chain over its working range; exit 2 on failure")
    check.add_argument("machine", help="shipped machine name or a machine YAML file")
    check.set_defaults(run=run_check)
    imp = actions.add_parser("import", help="read an MJCF with closed loops into a machine file; exit 2 if unsupported")
    imp.add_argument("model", help="MJCF file (slide joints for the actuators, connect equalities closing the loops)")
    imp.add_argument("-o", "--output", type=Path, required=True, metavar="MACHINE.yaml", help="machine file to write")
    imp.add_argument("--tcp", metavar="SITE_OR_BODY", help="the TCP: a site or body name (default: site 'tcp')")
    imp.add_argument(
        "--lock", action="append", default=[], metavar="JOINT=VALUE", help="hold a joint (e.g. slewing) at VALUE"
    )
    imp.add_argument("--plane", choices=("auto", "xz", "xy", "yz"), default="auto", help="plane of motion")
    imp.add_argument("--samples", type=int, default=40, help="random states of the round trip (default: 40)")
    imp.set_defaults(run=run_import)


def _range(values: tuple[float, float], unit: str) -> str:
    return f"[{values[0]:+.4f}, {values[1]:+.4f}] {unit}"


def describe(machine: Machine) -> list[str]:
    """The lines ``machine show`` prints."""
    lines = [f"{machine.name}  (gravity {machine.gravity:g} m/s^2)", f"source: {' '.join(machine.source.split())}"]
    lines.append("links:")
    for link in machine.links:
        where = "root" if link.parent is None else f"{link.joint_kind} joint {link.joint} on {link.parent}"
        span = "" if link.joint_range is None else f", working range {_range(link.joint_range, link.unit)}"
        lines.append(f"  {link.name:<16} {where}{span}; mass {link.mass:.3f} kg in {len(link.parts)} part(s)")
    lines.append("chains:")
    for chain in machine.chains:
        act = chain.actuator
        link = machine.joint_link(chain.joint)
        unit = link.unit
        head = f"  {chain.name:<10} {chain.kind} driving {chain.joint}; EMLA {act.emla}"
        lines.append(head + (f", hydraulic cylinder {act.hydraulic_cylinder}" if act.hydraulic_cylinder else ""))
        for pivot in chain.pivots:
            lines.append(f"      pivot {pivot.role:<8} on {pivot.link:<14} at {np.round(pivot.position, 5).tolist()} m")
        if chain.linkage is not None:
            lk = chain.linkage
            lines.append(
                f"      rocker {lk.rocker_length:g} m, coupler {lk.coupler_length:g} m, pin side {lk.pin_side:+d}"
            )
        x0 = act.retracted_length
        lengths = (
            "" if x0 is None else f", retracted {x0:.4f} m (Lc0 {act.piston_offset:.4f} + Lc {act.rod_length:.4f})"
        )
        lines.append(f"      stroke {act.stroke:.4f} m{lengths}; usable stroke {_range(usable_stroke(chain), 'm')}")
        working = link.joint_range or (0.0, 0.0)
        x = joint_to_stroke(machine, chain, np.linspace(*working, 201))
        reach = reachable_joint_range(machine, chain)
        shown = "none" if reach is None else _range(reach, unit)
        lines.append(
            f"      working range {_range(working, unit)} uses x in [{x.min():.4f}, {x.max():.4f}] m; reachable {shown}"
        )
        body_mass = sum(b.mass for b in (act.cylinder_body, act.rod_body) if b is not None)
        if chain.linkage is not None:
            body_mass += sum(b.mass for b in (chain.linkage.rocker_body, chain.linkage.coupler_body) if b is not None)
        lines.append(f"      chain bodies {body_mass:.3f} kg")
    total = sum(link.mass for link in machine.links) + sum(
        b.mass
        for c in machine.chains
        for b in (
            c.actuator.cylinder_body,
            c.actuator.rod_body,
            *(() if c.linkage is None else (c.linkage.rocker_body, c.linkage.coupler_body)),
        )
        if b is not None
    )
    lines.append(
        f"total moving and fixed mass {total:.3f} kg; TCP on {machine.tcp_link} at {list(machine.tcp.position)} m"
    )
    lines.append("decision variables:")
    for variable, value in zip(machine.decision_variables, machine.design_values(), strict=True):
        on = f" of pivot {variable.pivot}" if variable.pivot else ""
        bounds = f"[{variable.low:.5g}, {variable.high:.5g}] m"
        lines.append(f"  {variable.key:<14} {variable.kind}{on} = {value:.5f} m, bounds {bounds}")
    if not machine.decision_variables:
        lines.append("  none")
    plant = machine.realistic_plant or "realistic (the shipped plant: the XS 031's estimates; this file names none)"
    lines.append(f"realistic plant (simulate --plant realistic): {plant}")
    return lines


def run_show(args: argparse.Namespace) -> int:
    """Print the machine and write its drawing."""
    machine = load_machine(args.machine)
    for line in describe(machine):
        print(line)
    if not args.no_figure:
        from hiab_sim.machine.drawing import save_drawing

        stem = Path(str(args.machine)).stem
        path = args.figure or Path(f"{stem}.png" if stem.endswith("machine") else f"{stem}_machine.png")
        print(f"drawing: {save_drawing(machine, path)}")
    return 0


def run_check(args: argparse.Namespace) -> int:
    """Check the assembly; one line per failure, exit 2 when anything fails."""
    machine = load_machine(args.machine, check_assembly=False)
    failures = check_machine(machine)
    for failure in failures:
        print(f"FAIL {failure}")
    if failures:
        return 2
    print(f"{machine.name}: every chain assembles over its working range ({len(machine.chains)} chains)")
    return 0


def _locks(items: list[str]) -> dict[str, float]:
    from hiab_sim.errors import InvalidInputError

    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise InvalidInputError("--lock", item, "must be JOINT=VALUE with VALUE a number (rad or m)") from None
        if not sep or not name.strip():
            raise InvalidInputError("--lock", item, "must be JOINT=VALUE")
        if not math.isfinite(out[name.strip()]):
            raise InvalidInputError("--lock", item, "VALUE must be a finite number (rad or m)")
    return out


def run_import(args: argparse.Namespace) -> int:
    """Import the MJCF, check it, print the round trip, then write the file (nothing written on failure)."""
    import sys

    from hiab_sim.atomic_io import write_atomic
    from hiab_sim.errors import InvalidInputError
    from hiab_sim.machine.loader import machine_from_dict
    from hiab_sim.machine.mjcf_import.importer import UnsupportedMJCFError, import_mjcf
    from hiab_sim.machine.mjcf_import.round_trip import fit_ranges, machine_yaml, round_trip
    from hiab_sim.yaml_fields import parse_yaml

    if args.samples < 1:
        raise InvalidInputError("--samples", args.samples, "must be >= 1 (random states of the round trip)")
    if not args.output.parent.is_dir():
        raise InvalidInputError("--output", str(args.output), "its folder must exist")
    if args.output.is_dir():
        raise InvalidInputError("--output", str(args.output), "must name a file, not an existing folder")
    try:
        imported = import_mjcf(args.model, tcp=args.tcp, locks=_locks(args.lock), plane=args.plane)
    except UnsupportedMJCFError as error:
        for line in error.lines:
            print(f"hiab-sim machine import: unsupported: {line}", file=sys.stderr)
        return 2
    for line in imported.warnings:
        print(f"hiab-sim machine import: warning: {line}", file=sys.stderr)
    machine = fit_ranges(imported)
    command = " ".join(["hiab-sim machine import", str(args.model), *(f"--lock {x}" for x in args.lock)])
    text = machine_yaml(imported, command + (f" --tcp {args.tcp}" if args.tcp else ""))
    machine = machine_from_dict(parse_yaml(text), origin=str(args.output), check_assembly=False)  # as written
    failures = check_machine(machine)
    for failure in failures:
        print(f"hiab-sim machine import: FAIL {failure}", file=sys.stderr)
    if failures:
        return 2
    errors = round_trip(imported, machine, samples=args.samples)
    for line in describe(machine):
        print(line)
    for path, value in errors.items():
        print(
            f"round trip ({args.samples} random loop-consistent states): {path} vs the MJCF, "
            f"max relative force difference {value:.2e}"
        )
    write_atomic(args.output, text)
    print(f"wrote {args.output}")
    return 0

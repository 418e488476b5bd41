"""``hiab-sim crane``: print a summary of a crane description (chains, lengths, ranges, masses)."""

from __future__ import annotations

import argparse

import numpy as np

from hiab_sim.cli.options import add_crane_option, names_machine_file
from hiab_sim.crane import mechanism
from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import ConfigError


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "crane",
        help="print a summary of a crane description",
        description=(
            "Print a crane description: for each closed chain (cylinder base pivot, boom hinge, rod-end pivot) its "
            "link lengths, the cylinder's stroke and usable stroke, the joint range the chain can reach and the "
            "working range the study uses; the telescope; every body with its mass."
        ),
    )
    add_crane_option(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Print the crane summary."""
    if names_machine_file(str(args.crane)):
        raise ConfigError(f"--crane {args.crane}: a machine file, which 'hiab-sim machine show {args.crane}' prints")
    crane = load_crane(args.crane)
    print(f"{crane.name}  (gravity {crane.gravity} m/s^2)")
    print(f"source: {crane.source}")
    for chain in crane.chains:
        xi = chain.default_lengths
        x_min, x_max = mechanism.stroke_bounds(chain, xi)
        low, high = mechanism.reachable_joint_range(chain, xi)
        work = chain.joint_range
        print(
            f"{chain.name:>5} chain: L = {xi.L:.4f} m, L1 = {chain.L1:.4f} m, Lc0 = {xi.Lc0:.4f} m, "
            f"Lc = {xi.Lc:.4f} m, stroke {chain.stroke:.3f} m (usable [{x_min:.4f}, {x_max:.4f}] m)"
        )
        print(
            f"       reachable theta [{low:+.4f}, {high:+.4f}] rad"
            f" = [{np.degrees(low):+.1f}, {np.degrees(high):+.1f}] deg;"
            f" working range [{work[0]:+.4f}, {work[1]:+.4f}] rad"
        )
    tele = crane.telescope
    print(f"telescope: stroke {tele.stroke:.3f} m, rod {tele.rod_length:.3f} m, range {list(tele.joint_range)} m")
    total = sum(body.mass for body in crane.bodies)
    print(f"bodies: {len(crane.bodies)}, total mass {total:.2f} kg")
    for body in crane.bodies:
        print(f"  {body.name:<20} {body.mass:10.3f} kg on link {body.link}")
    return 0

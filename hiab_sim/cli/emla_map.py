"""``hiab-sim emla-map``: Plot an EMLA efficiency map over load force and velocity (issue 5).

Not implemented yet: the subcommand is registered so that ``--help`` lists it, and it exits
with status 2 and a message until its issue lands.
"""

from __future__ import annotations

import argparse

from hiab_sim.errors import HiabSimError


def add_parser(subparsers: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Register the subcommand."""
    parser = subparsers.add_parser("emla-map", help="Plot an EMLA efficiency map over load force and velocity (issue 5). (not implemented yet)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Report that the subcommand is not available yet."""
    raise HiabSimError("'emla-map' is not implemented yet")

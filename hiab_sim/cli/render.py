"""``hiab-sim render``: Render a playback video of an optimisation result off-screen (issue 7).

Not implemented yet: the subcommand is registered so that ``--help`` lists it, and it exits
with status 2 and a message until its issue lands.
"""

from __future__ import annotations

import argparse

from hiab_sim.errors import HiabSimError


def add_parser(subparsers: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Register the subcommand."""
    parser = subparsers.add_parser("render", help="Render a playback video of an optimisation result off-screen (issue 7). (not implemented yet)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Report that the subcommand is not available yet."""
    raise HiabSimError("'render' is not implemented yet")

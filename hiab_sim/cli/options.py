"""Options that several subcommands declare alike: ``--crane``, ``--machine`` and ``--out`` (an output folder).

Each subcommand keeps its own help text (the CLI reference is generated from it; ``--out``'s names
only where the output goes by default); the option's name, default and metavar are declared here once.
"""

from __future__ import annotations

import argparse

#: The crane preset ``--crane`` takes when it is not given.
DEFAULT_CRANE = "xs031"

#: ``--crane``'s help where the subcommand says nothing more about it.
CRANE_HELP = f"preset name or YAML file (default: {DEFAULT_CRANE})"


def add_crane_option(parser: argparse.ArgumentParser, help: str = CRANE_HELP) -> None:
    """``--crane``: a crane preset name or YAML file, default :data:`DEFAULT_CRANE`."""
    parser.add_argument("--crane", default=DEFAULT_CRANE, help=help)


def add_out_option(parser: argparse.ArgumentParser, default: str) -> None:
    """``--out DIR``: the output folder; ``default`` says where the output goes without one."""
    parser.add_argument("--out", metavar="DIR", help=f"output folder (default: {default})")


def add_machine_option(parser: argparse.ArgumentParser, help: str) -> None:
    """``--machine``: a shipped machine file's name or a machine file's path (no default: the crane file is used)."""
    parser.add_argument("--machine", metavar="NAME|FILE", help=help)

"""Options that several subcommands declare alike: ``--crane``, ``--machine`` and ``--out`` (an output folder).

Each subcommand keeps its own help text (the CLI reference is generated from it; ``--out``'s names
only where the output goes by default); the option's name, default and metavar are declared here once.
Where a subcommand has both, ``--crane`` is also an alias of ``--machine`` (:func:`resolve_crane_alias`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import yaml

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
    parser.add_argument("--machine", metavar="NAME|FILE", help=f"{help}; --crane naming a machine file is an alias")


def _is_machine_file(value: str) -> bool:
    """Whether ``value`` is a YAML file of the machine format (top-level ``links`` and ``chains``)."""
    path = Path(value)
    if not path.is_file():
        return False
    try:
        top = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return False  # the crane loader reads it again and names what is wrong
    return isinstance(top, dict) and {"links", "chains"} <= set(top)


def resolve_crane_alias(args: argparse.Namespace) -> None:
    """``--crane`` kept as an alias of ``--machine``: a ``--crane`` that names a machine file moves to ``--machine``.

    Only on a subcommand with both options and no ``--machine`` given. A machine file is a shipped
    machine's name that is no shipped crane's (``exact``; ``xs031`` stays the crane file) or a YAML
    file with the machine format's ``links`` and ``chains``; anything else stays a crane file.
    """
    crane = getattr(args, "crane", None)
    if crane is None or not hasattr(args, "machine") or args.machine is not None:
        return
    if names_machine_file(str(crane)):
        args.machine, args.crane = crane, None


def names_machine_file(value: str) -> bool:
    """Whether a ``--crane`` value names a machine file: a shipped machine that is no shipped crane, or such a YAML."""
    from hiab_sim.resources import shipped_names

    if value in shipped_names("crane"):
        return False
    return value in shipped_names("machine") or _is_machine_file(value)

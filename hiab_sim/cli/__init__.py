"""The ``hiab-sim`` console script: one argparse parser, one module per subcommand.

Every subcommand module in :data:`SUBCOMMANDS` exposes ``add_parser(subparsers)`` and
``run(args) -> int``. A :class:`~hiab_sim.errors.HiabSimError` (bad input) is printed on one
line and the process exits with status 2, without a traceback; a solver failure exits 1, a study with no
feasible point within its bounds exits 3 (the message names the binding limit). Output into a closed
pipe (``hiab-sim crane | head -1``) ends the command quietly with the shell's status for SIGPIPE (141).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Sequence

from hiab_sim import __version__
from hiab_sim._gl import check_gl_backend, select_gl_backend
from hiab_sim.cli.options import resolve_crane_alias
from hiab_sim.errors import HiabSimError, InfeasibleStudyError, SolverError

#: Subcommands that import MuJoCo: its OpenGL backend is checked before they run.
USES_MUJOCO = {"mjcf", "validate", "optimize", "render", "simulate", "sweep", "pareto"}

#: Exit status of a command whose output pipe was closed by its reader (128 + SIGPIPE, as a shell reports it).
BROKEN_PIPE_STATUS = 141

#: Subcommand name -> module under ``hiab_sim.cli`` that implements it.
SUBCOMMANDS: dict[str, str] = {
    "crane": "crane_info",
    "machine": "machine",
    "mjcf": "mjcf",
    "validate": "validate",
    "emla-map": "emla_map",
    "optimize": "optimize",
    "report": "report",
    "render": "render",
    "compare": "compare",
    "simulate": "simulate",
    "energy-map": "energy_map",
    "sweep": "sweep",
    "pareto": "pareto",
}


def build_parser() -> argparse.ArgumentParser:
    """Return the top-level parser with every subcommand registered."""
    parser = argparse.ArgumentParser(
        prog="hiab-sim",
        description=(
            "Energy-optimal mounting of electromechanical linear actuators on planar parallel-serial machines "
            "(loader cranes, excavator arms): the HIAB XS 031 and the eXact arm ship, any other is a machine file."
        ),
    )
    parser.add_argument("--version", action="version", version=f"hiab-sim {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module_name in SUBCOMMANDS.values():
        module = importlib.import_module(f"hiab_sim.cli.{module_name}")
        module.add_parser(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; return the process exit status (141 when the reader of stdout closed the pipe)."""
    try:
        try:
            status = _main(argv)
        finally:  # also after --help's SystemExit: a closed pipe shows on this flush when the output was buffered
            sys.stdout.flush()
    except BrokenPipeError:
        # The reader is gone: point stdout at /dev/null so the interpreter's final flush cannot fail again.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
        return BROKEN_PIPE_STATUS
    return status


def _main(argv: Sequence[str] | None) -> int:
    select_gl_backend()  # before any subcommand module imports MuJoCo or dm_control
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    resolve_crane_alias(args)
    try:
        if args.command in USES_MUJOCO:
            check_gl_backend()
        return int(args.run(args))
    except InfeasibleStudyError as error:
        print(f"hiab-sim {args.command}: infeasible: {error}", file=sys.stderr)
        return 3
    except SolverError as error:
        print(f"hiab-sim {args.command}: solver failed: {error}", file=sys.stderr)
        return 1
    except HiabSimError as error:
        print(f"hiab-sim {args.command}: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"hiab-sim {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())

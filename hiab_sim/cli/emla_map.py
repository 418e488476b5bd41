"""``hiab-sim emla-map``: plot an EMLA efficiency map over load force and rod velocity."""

from __future__ import annotations

import argparse
from pathlib import Path

from hiab_sim.emla.config import load_emla_set
from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.emla.params import EmlaParams
from hiab_sim.errors import InvalidInputError


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "emla-map",
        help="Plot an EMLA efficiency map over load force and velocity (all four quadrants).",
        description=(
            "Efficiency of one EMLA over load force and rod velocity at zero acceleration, with the "
            "feasible envelope (peak torque, rated speed, voltage) and the hydraulic cylinder it replaces. "
            "An EMLA file serves any machine whose actuators it names (a study pairs the two: emla: in the "
            "study file); --emla exact maps the eXact arm's."
        ),
    )
    parser.add_argument(
        "--actuator",
        metavar="NAME",
        help="an actuator of the EMLA file, by its name there (default: the file's first actuator)",
    )
    parser.add_argument(
        "--emla",
        "--config",
        dest="emla",
        metavar="NAME|EMLA.yaml",
        help="EMLA file: a shipped name (xs031, paper, exact) or a YAML file (default: the XS 031 preset)",
    )
    parser.add_argument("-o", "--output", metavar="FILE.png", help="figure path (default: emla_map_ACTUATOR.png)")
    parser.add_argument("--csv", metavar="FILE.csv", help="also write the grid as CSV")
    parser.add_argument("--npz", metavar="FILE.npz", help="also write the grid as NPZ")
    parser.add_argument("--resolution", type=int, default=161, help="grid points per axis (default: 161)")
    parser.set_defaults(run=run)


def chosen_actuator(emlas: EmlaSet, name: str | None) -> EmlaParams:
    """The EMLA called ``name`` in the set (its first when ``None``).

    Raises:
        InvalidInputError: ``name`` is not one of the file's actuators (the message lists them).

    """
    if name is None:
        return emlas.params[0]
    if name not in emlas.names:
        raise InvalidInputError(
            "--actuator", name, f"must be one of the EMLA file's actuators: {', '.join(emlas.names)}"
        )
    return emlas[name]


def run(args: argparse.Namespace) -> int:
    """Compute the map, write the requested files and print a one-line summary per file."""
    from hiab_sim.emla.maps import efficiency_map, plot_efficiency_map, save_csv, save_npz
    from hiab_sim.figure_io import save_png

    params = chosen_actuator(load_emla_set(args.emla), args.actuator)
    emap = efficiency_map(params, n_force=args.resolution, n_velocity=args.resolution)
    output = Path(args.output) if args.output else Path(f"emla_map_{params.name}.png")
    targets: list[tuple[str, Path]] = [("figure", output)]
    targets += [(kind, Path(p)) for kind, p in (("csv", args.csv), ("npz", args.npz)) if p]
    for kind, path in targets:
        if not path.parent.is_dir():
            raise InvalidInputError(f"{kind} path", str(path), "its folder must exist")
    fig = plot_efficiency_map(emap)
    save_png(fig, output, dpi=150)
    if args.csv:
        save_csv(emap, args.csv)
    if args.npz:
        save_npz(emap, args.npz)
    print(
        f"{params.name}: peak force {emap.peak_force / 1e3:.1f} kN"
        + (f" (hydraulic {params.hydraulic_push_force / 1e3:.1f} kN)" if params.hydraulic_push_force else "")
        + f", top speed {emap.top_speed:.4f} m/s"
    )
    for kind, path in targets:
        print(f"wrote {kind}: {path}")
    return 0

"""``hiab-sim emla-map``: plot an EMLA efficiency map over load force and rod velocity."""

from __future__ import annotations

import argparse
from pathlib import Path

from hiab_sim.emla.config import load_emla_set
from hiab_sim.emla.emla_set import EmlaSet
from hiab_sim.emla.params import EmlaParams
from hiab_sim.errors import InvalidInputError

#: Grid points per axis the map allows: three give both signs of force and velocity around zero; at the
#: upper end the map's evaluation holds 1.5 GB (measured: 4 s, the XS 031 lift), its memory growing as n^2.
RESOLUTION = (3, 2001)
#: Each output option and the file suffix it writes (the figure is PNG data, as ``render --still`` writes).
SUFFIXES = {"--output": ".png", "--csv": ".csv", "--npz": ".npz"}


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
    parser.add_argument(
        "-o", "--output", metavar="FILE.png", help="figure path, a PNG file (default: emla_map_ACTUATOR.png)"
    )
    parser.add_argument("--csv", metavar="FILE.csv", help="also write the grid as CSV")
    parser.add_argument("--npz", metavar="FILE.npz", help="also write the grid as NPZ")
    parser.add_argument(
        "--resolution",
        type=int,
        default=161,
        help=f"grid points per axis, {RESOLUTION[0]} to {RESOLUTION[1]} (default: 161)",
    )
    parser.set_defaults(run=run)


def check_outputs(args: argparse.Namespace, output: Path) -> list[tuple[str, Path]]:
    """The files to write as (kind, path), each checked before anything is computed.

    Raises:
        InvalidInputError: ``--resolution`` out of :data:`RESOLUTION`, a path whose suffix is not its
            option's (:data:`SUFFIXES`; numpy would add ``.npz`` to another name), or whose folder does not exist.

    """
    low, high = RESOLUTION
    if not low <= args.resolution <= high:
        raise InvalidInputError("--resolution", args.resolution, f"must be an integer from {low} to {high}")
    paths = {"--output": output, "--csv": args.csv, "--npz": args.npz}
    targets = []
    for option, path in paths.items():
        if path is None:
            continue
        path = Path(path)
        if path.suffix.lower() != SUFFIXES[option]:
            raise InvalidInputError(option, str(path), f"must end with {SUFFIXES[option]}")
        if not path.parent.is_dir():
            raise InvalidInputError(option, str(path), "its folder must exist")
        targets.append(("figure" if option == "--output" else option[2:], path))
    return targets


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
    output = Path(args.output) if args.output else Path(f"emla_map_{params.name}.png")
    targets = check_outputs(args, output)
    emap = efficiency_map(params, n_force=args.resolution, n_velocity=args.resolution)
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

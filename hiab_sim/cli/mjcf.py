"""``hiab-sim mjcf``: write the MJCF crane model for a link-length set.

``--lengths`` takes six numbers in metres, comma-separated, lift chain first:
``L,Lc0,Lc,L,Lc0,Lc`` (seed eq. Xi). The file is written atomically (a temporary file in the
target folder, then ``os.replace``), loads with ``mujoco.MjModel.from_xml_path`` and opens in
``python -m mujoco.viewer --mjcf=FILE`` standing at ``home``: the crane at the middle of its working
ranges, loop-consistent, placed there by the joints' ``ref`` so that it is qpos0. The file is the
simulation model (:mod:`hiab_sim.model.drives`): the EMLAs' reflected rotor inertia as armature, screw
friction as damping, joint ranges at the stops, and actuators with the EMLA force range. Its
actuators are stroke servos around home (ctrl = stroke change [m], 0 holds home with the static
forces from inverse dynamics; critically damped at 1 Hz on the reflected inertia), so the
viewer's sliders move the crane. The keyframe ``home`` holds the same pose.

``--from-result RUN_DIR [--design optimal|initial]`` exports the exact (full-precision) design of
an optimisation result, with the crane the result was computed for.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from hiab_sim.atomic_io import write_atomic
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import InvalidInputError

#: Natural frequency of the viewer file's stroke servos [Hz].
SERVO_FREQUENCY_HZ = 1.0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "mjcf",
        help="write the MJCF crane model for a link-length set",
        description="Write the MuJoCo MJCF model of the crane (closed chains as connect equalities).",
    )
    parser.add_argument("--crane", default="xs031", help="preset name or YAML file (default: xs031)")
    parser.add_argument(
        "--lengths",
        metavar="L,Lc0,Lc,L,Lc0,Lc",
        help="link lengths [m], lift chain then tilt chain (default: the crane's own)",
    )
    parser.add_argument(
        "--from-result",
        metavar="RUN_DIR",
        help="export a design of an optimisation result folder (exact lengths and its crane)",
    )
    parser.add_argument(
        "--design",
        choices=("optimal", "initial"),
        default="optimal",
        help="with --from-result: which design (default: optimal)",
    )
    parser.add_argument(
        "--stroke-margin",
        type=float,
        default=0.0,
        metavar="M",
        help="keep M [m] of stroke free at both ends of each chain's joint range, as a study's build.stroke_margin "
        "(the rounded designs of hiab-sim optimize serve that range; default: 0, the crane's full range)",
    )
    parser.add_argument("-o", "--output", default="crane.xml", metavar="FILE.xml", help="default: crane.xml")
    parser.set_defaults(run=run)


def parse_lengths(text: str) -> LinkLengths:
    """Parse ``L,Lc0,Lc,L,Lc0,Lc`` (lift, then tilt) in metres.

    Raises:
        InvalidInputError: not six finite numbers (field ``--lengths``).

    """
    parts = [p.strip() for p in text.split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise InvalidInputError("--lengths", text, "must be six numbers L,Lc0,Lc,L,Lc0,Lc (lift, tilt)", "m") from None
    if len(values) != 6 or not all(math.isfinite(v) for v in values):
        raise InvalidInputError("--lengths", text, "must be six finite numbers L,Lc0,Lc,L,Lc0,Lc (lift, tilt)", "m")
    return LinkLengths.from_array(values)


def home_keyframe(crane: Crane, lengths: LinkLengths) -> tuple[np.ndarray, np.ndarray]:
    """Loop-consistent qpos at the middle of the working ranges and the forces that hold it [N]."""
    from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
    from hiab_sim.dynamics.samples import JointSamples

    ranges = [*(chain.joint_range for chain in crane.chains), crane.telescope.joint_range]
    rest = JointSamples.at_rest([[0.5 * (low + high) for low, high in ranges]])
    dynamics = MujocoInverseDynamics(crane, lengths)
    qpos, _, _ = dynamics.state(rest)
    return qpos[0], dynamics(rest).force[0]


def _crane_and_lengths(args: argparse.Namespace) -> tuple[Crane, LinkLengths]:
    """The crane and design to export: from ``--from-result`` or from ``--crane`` and ``--lengths``."""
    if args.from_result is None:
        crane = load_crane(args.crane)
        return crane, parse_lengths(args.lengths) if args.lengths else crane.default_lengths
    if args.lengths:
        raise InvalidInputError("--lengths", args.lengths, "cannot be combined with --from-result")
    from hiab_sim.results.read import design_lengths, read_result, result_crane

    result = read_result(args.from_result)
    return result_crane(args.from_result, result.crane), design_lengths(result, args.design)


def run(args: argparse.Namespace) -> int:
    """Build the model, write it and print a one-line summary."""
    import mujoco

    from hiab_sim.crane.tolerance import buildable_crane
    from hiab_sim.model.mjcf import to_xml

    crane, lengths = _crane_and_lengths(args)
    crane = buildable_crane(crane, args.stroke_margin, field="--stroke-margin")
    from hiab_sim.emla import load_emla_set
    from hiab_sim.model.drives import HomePose, SlideDrives, servo_gains
    from hiab_sim.model.mjcf import build_model

    qpos, force = home_keyframe(crane, lengths)
    names = [build_model(crane, lengths).joint(j).name for j in range(len(qpos))]
    drives = SlideDrives.from_emla(load_emla_set())
    home = HomePose(
        qpos=dict(zip(names, map(float, qpos), strict=True)),
        force=(float(force[0]), float(force[1]), float(force[2])),
        servo=servo_gains(np.asarray(drives.armature), SERVO_FREQUENCY_HZ),
    )
    text = to_xml(crane, lengths, keyframes={"home": (qpos, np.zeros(3))}, drives=drives, home=home)
    model = mujoco.MjModel.from_xml_string(text)  # what the file will load as
    output = Path(args.output)
    if not output.parent.is_dir():
        raise InvalidInputError("--output", str(output), "its folder must exist")
    write_atomic(output, text)
    xi = ", ".join(f"{v:.10g}" for v in lengths.as_array())
    print(f"wrote {output}: {crane.name}, Xi = [{xi}] m, {model.nbody - 1} bodies, {model.nv} dofs")
    return 0

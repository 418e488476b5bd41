"""``hiab-sim mjcf``: write the MJCF model of a crane file or a machine file for one design.

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

``--machine NAME|FILE [--design chain.var=value ...]`` writes any machine file's model instead: the
generic MJCF of :mod:`hiab_sim.machine.dynamics.mjcf_build` for that design (the file's values where
no item sets one), with a loop-consistent keyframe ``home`` and framed cameras
(:mod:`hiab_sim.machine_mjcf`); its motors take the actuator force [N]. ``--from-result RUN_DIR``
of a machine file's result exports its ``--design initial|optimal`` with the machine it was computed for.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from hiab_sim.atomic_io import write_atomic
from hiab_sim.cli.options import DEFAULT_CRANE, add_crane_option, add_machine_option
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import ConfigError, HiabSimError, InvalidInputError
from hiab_sim.results.design_values import crane_lengths

#: Natural frequency of the viewer file's stroke servos [Hz].
SERVO_FREQUENCY_HZ = 1.0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the subcommand."""
    parser = subparsers.add_parser(
        "mjcf",
        help="write the MJCF model of a machine for one design",
        description=(
            "Write the MuJoCo MJCF model of a crane file (--crane, --lengths) or a machine file (--machine, --design) "
            "for one design: the closed chains as connect equalities, the EMLAs as stroke servos around the home "
            "pose (a machine file's: force motors), and cameras that frame the machine. "
            "Opens in 'python -m mujoco.viewer --mjcf=FILE'."
        ),
    )
    add_crane_option(parser)
    add_machine_option(parser, "a machine file (shipped: xs031, exact) instead of a crane file: its generic MJCF")
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
        action="extend",
        nargs="+",
        metavar="DESIGN",
        help="with --from-result: optimal or initial (default: optimal); with --machine: chain.var=value items [m] "
        "(the file's values elsewhere)",
    )
    parser.add_argument(
        "--stroke-margin",
        type=float,
        default=0.0,
        metavar="M",
        help="keep M [m] of stroke free at both ends of each chain's joint range, as a study's build.stroke_margin "
        "(the rounded designs of hiab-sim optimize serve that range; default: 0, the crane's full range)",
    )
    parser.add_argument(
        "-o", "--output", metavar="FILE.xml", help="default: crane.xml (a crane file), machine.xml (a machine file)"
    )
    # --crane is None unless given: with --from-result the result names its machine, and a --crane there is refused
    parser.set_defaults(run=run, crane=None)


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


#: Poses per joint over its working range that the cameras are fitted to (every combination).
CAMERA_POSES_PER_JOINT = 4


def workspace_qpos(crane: Crane, lengths: LinkLengths) -> np.ndarray:
    """Loop-consistent qpos (P, nq) at every combination of poses over each joint's working range."""
    from hiab_sim.crane.mechanism import reachable_joint_range
    from hiab_sim.dynamics.mujoco_id import MujocoInverseDynamics
    from hiab_sim.dynamics.samples import JointSamples

    ranges = []
    for chain in crane.chains:  # the working range, within what these lengths reach (1e-9 rad inside)
        reach = reachable_joint_range(chain, getattr(lengths, chain.name))
        ranges.append((max(chain.joint_range[0], reach[0]) + 1e-9, min(chain.joint_range[1], reach[1]) - 1e-9))
    ranges.append(crane.telescope.joint_range)
    axes = [np.linspace(low, high, CAMERA_POSES_PER_JOINT) for low, high in ranges]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(ranges))
    qpos, _, _ = MujocoInverseDynamics(crane, lengths).state(JointSamples.at_rest(grid))
    return np.asarray(qpos)


def frame_cameras(text: str, model: object, crane: Crane, lengths: LinkLengths, names: list[str]) -> str:
    """The MJCF with its cameras (``side``, ``perspective``) placed to frame the machine at every pose.

    The poses are :func:`workspace_qpos`; the cameras hold the visible geoms' bounding boxes at all
    of them (:func:`hiab_sim.render.camera.framed_cameras`), whatever the link lengths.
    """
    from xml.etree import ElementTree

    import mujoco

    from hiab_sim.machine_mjcf import place_cameras
    from hiab_sim.render.camera import geom_corners

    assert isinstance(model, mujoco.MjModel)
    data = mujoco.MjData(model)
    address = [int(model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)]) for n in names]
    corners = []
    for q in workspace_qpos(crane, lengths):
        data.qpos[address] = q
        mujoco.mj_kinematics(model, data)
        corners.append(geom_corners(model, data))
    root = ElementTree.fromstring(text)
    world = root.find("worldbody")
    assert world is not None
    place_cameras(world, np.concatenate(corners))
    return ElementTree.tostring(root, encoding="unicode")


def given_chain(lengths: LinkLengths, message: str) -> str:
    """The lengths the user gave for the chain a message names (``lift.joint_range ...``), else all of them."""
    from dataclasses import fields

    for chain in (f.name for f in fields(LinkLengths)):
        if message.startswith(f"{chain}."):
            xi = getattr(lengths, chain)
            return f"the {chain} chain given as L = {xi.L:g} m, Lc0 = {xi.Lc0:g} m, Lc = {xi.Lc:g} m"
    return "the lengths given [" + ", ".join(f"{v:g}" for v in lengths.as_array()) + "] m"


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
        crane = load_crane(args.crane or DEFAULT_CRANE)
        return crane, parse_lengths(args.lengths) if args.lengths else crane.default_lengths
    if args.lengths:
        raise InvalidInputError("--lengths", args.lengths, "cannot be combined with --from-result")
    from hiab_sim.results.read import design_lengths, read_result, result_crane

    result = read_result(args.from_result)
    return result_crane(args.from_result, result.crane), crane_lengths(
        design_lengths(result, args.design), "--from-result"
    )


def _result_design(args: argparse.Namespace) -> str:
    """The one ``--design`` of ``--from-result``: ``optimal`` (default) or ``initial``."""
    items = args.design or ["optimal"]
    if len(items) != 1 or items[0] not in ("optimal", "initial"):
        raise InvalidInputError("--design", " ".join(items), "with --from-result must be optimal or initial")
    return str(items[0])


def _is_machine_result(run_dir: str) -> bool:
    from hiab_sim.machine.design import MachineDesign
    from hiab_sim.results.read import read_result

    return isinstance(read_result(run_dir).optimal.lengths, MachineDesign)


def run(args: argparse.Namespace) -> int:
    """Build the model, write it and print a one-line summary."""
    if args.from_result is not None and args.crane is not None:
        raise InvalidInputError(
            "--crane", args.crane, "cannot be combined with --from-result (the result names its machine)"
        )
    if args.machine is not None and args.crane is not None:
        raise InvalidInputError("--crane", args.crane, "cannot be combined with --machine")
    machine_file = args.machine is not None or (args.from_result is not None and _is_machine_result(args.from_result))
    args.output = args.output or ("machine.xml" if machine_file else "crane.xml")
    if machine_file:
        from hiab_sim.cli.mjcf_machine import run_machine

        return run_machine(args, _result_design(args) if args.from_result is not None else None)
    if args.from_result is not None:
        args.design = _result_design(args)
    elif args.design:
        raise InvalidInputError("--design", " ".join(args.design), "needs --from-result or --machine")
    import mujoco

    from hiab_sim.crane.tolerance import buildable_crane
    from hiab_sim.model.mjcf import to_xml

    crane, lengths = _crane_and_lengths(args)
    crane = buildable_crane(crane, args.stroke_margin, field="--stroke-margin")
    from hiab_sim.emla import load_emla_set
    from hiab_sim.model.drives import HomePose, SlideDrives, servo_gains
    from hiab_sim.model.mjcf import build_model

    try:
        qpos, force = home_keyframe(crane, lengths)
    except HiabSimError as error:
        if not args.lengths:
            raise
        raise ConfigError(f"--lengths {args.lengths}: {given_chain(lengths, str(error))}: {error}") from None
    names = [build_model(crane, lengths).joint(j).name for j in range(len(qpos))]
    drives = SlideDrives.from_emla(load_emla_set())
    home = HomePose(
        qpos=dict(zip(names, map(float, qpos), strict=True)),
        force=(float(force[0]), float(force[1]), float(force[2])),
        servo=servo_gains(np.asarray(drives.armature), SERVO_FREQUENCY_HZ),
    )
    text = to_xml(crane, lengths, keyframes={"home": (qpos, np.zeros(3))}, drives=drives, home=home)
    model = mujoco.MjModel.from_xml_string(text)  # what the file will load as
    text = frame_cameras(text, model, crane, lengths, names)
    model = mujoco.MjModel.from_xml_string(text)
    output = Path(args.output)
    if not output.parent.is_dir():
        raise InvalidInputError("--output", str(output), "its folder must exist")
    write_atomic(output, text)
    xi = ", ".join(f"{v:.10g}" for v in lengths.as_array())
    print(f"wrote {output}: {crane.name}, Xi = [{xi}] m, {model.nbody - 1} bodies, {model.nv} dofs")
    return 0

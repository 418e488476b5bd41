"""Write ``exact_digging_cycle.csv`` and ``exact_grading_pass.csv``: two bucket-tip tasks of the eXact arm.

Run ``python optimize/make_excavator_cycles.py [OUT_DIR]`` (deterministic; it writes both CSVs into
OUT_DIR, by default next to this file, after checking every sample with a closed-form inverse
kinematics of hiab_sim/presets/exact_excavator.yaml). Columns ``t,x,y,tcp_angle``: time [s], the
bucket tip (TCP, point M) in the chassis frame {i} [m] (origin at the boom hinge B, x forward,
y up), and the world angle of the bucket frame's x axis, hinge L -> tip M [rad] (theta = alpha +
beta + gamma); the comment header of each file says where its numbers come from.

Digging cycle: the four segments of an excavator cycle (load bucket, swing loaded, dump bucket,
swing empty) of the Caterpillar Performance Handbook, Edition 47 (SEBD0351-47, January 2017),
"Cycle time estimating charts", p. 7-246, which gives 10 to 17 s cycles as practical when the
truck stands beside the excavator on the floor of the excavation (smaller machines cycling
faster). Our nominal split of a 14 s cycle (the handbook's table of segment times was not to hand:
a choice): load bucket 5.5 s (penetrate 1.5, drag 2.5, curl 1.5), swing loaded 3.0 s, dump 1.5 s,
swing empty 3.0 s, and 0.5 s at rest at each end. The swing itself is out of the arm's plane; in
the plane the arm lifts the bucket to the dump point and lowers it back while the house swings.
Grading pass (no published time found; chosen): lower the bucket to the ground (2.0 s), drag it
level at a fixed attitude 30 mm deep over 1.2 m (5.0 s, mean 0.24 m/s), lift it 0.3 m (1.5 s),
return to the start (3.0 s), 0.5 s at rest at each end.

The eXact's EMLAs are slower than a hydraulic mini excavator: 2250 rpm through 2444.16 rad/m is
0.0964 m/s of rod speed (emla_exact.yaml). Each move keeps its nominal time unless one of the
rods would then exceed 90 % of that speed; such a move is slowed (its time scaled, rounded up to
0.1 s) until the fastest rod runs at 90 %. The CSV headers give both times.

Every move is rest to rest along a straight line in (x, y, theta) with the septic timing law of
:func:`hiab_sim.study.references.kinds.septic_law` (C3: velocity, acceleration and jerk vanish at
each waypoint). Samples at 50 Hz, rounded to 10 um and 10 urad.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np
import yaml

from hiab_sim.errors import InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.kinematics.assembly import usable_stroke
from hiab_sim.machine.kinematics.closure import joint_to_actuator
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine.loader import load_machine
from hiab_sim.resources import shipped
from hiab_sim.study.references.kinds import septic_law

HERE = Path(__file__).resolve().parent
EMLA_FILE = HERE.parent / "hiab_sim" / "presets" / "emla_exact.yaml"
RATE = 50.0  #: Hz
Y_GROUND = -0.95737  #: m, read: exact_excavator.yaml notes.ground (eXactMPC yGround)
#: Height of the truck body's side boards above the ground [m], which the bucket tip clears at the
#: dump point. Choice (no published bed height found): a 1-2 t mini excavator loads 1-ton trucks
#: (Bobcat's announcement of its 1.9 t E20, dump height 8 ft 10 in = 2.69 m), whose contractor's
#: dump bodies have 12-24 in sides (Fleet Financials, "How to spec dump bodies for light- and
#: medium-duty trucks"); about 0.8-0.9 m of chassis and floor (estimate) plus 0.4-0.5 m of sides.
RIM_HEIGHT = 1.30
CLEARANCE = 0.05  #: m the tip stays above the rim while the bucket opens (choice)
#: Bucket (cutting edge) width [m] for the soil force; not a column of the CSVs. Choice: the eXact
#: source gives none; 0.40 m, a general-purpose bucket of a 1.5-2 t machine, whose cut below fills
#: about 40 l, a bucket of this class.
BUCKET_WIDTH = 0.40
CUT_DEPTH, CUT_LENGTH = 0.12, 0.80  #: m: w d L = 0.4 x 0.12 x 0.8 = 0.038 m^3 per cut (choice)
GRADE_DEPTH, GRADE_LENGTH = 0.03, 1.20  #: m (choice: a finishing pass)
SPEED_SHARE = 0.9  #: of the EMLA's top rod speed that a nominal move may use (choice: control margin)

Pose = tuple[float, float, float]  # tip x [m], tip y [m], theta [rad]


def _pose(x: float, height: float, theta_deg: float) -> Pose:
    """A waypoint: tip x [m], tip height above the ground [m], bucket angle [deg] -> (x, y, theta)."""
    return (x, Y_GROUND + height, math.radians(theta_deg))


def _hinge_pose(hinge: tuple[float, float], theta_deg: float, tip_length: float) -> Pose:
    """The tip pose for the bucket hinge at ``hinge`` (world x, y) [m] and the bucket at ``theta_deg``."""
    th = math.radians(theta_deg)
    return (hinge[0] + tip_length * math.cos(th), hinge[1] + tip_length * math.sin(th), th)


class Phase(NamedTuple):
    """One phase: what it is, its nominal time [s] and the pose it moves to (None: rest where it is)."""

    name: str
    nominal: float
    target: Pose | None


def digging_phases(tip_length: float) -> tuple[Pose, tuple[Phase, ...]]:
    """Start pose and phases of the digging cycle (geometry: choices inside the arm's workspace)."""
    start = _pose(2.45, 0.30, -110.0)  # bucket poised 0.3 m above the cut's start
    # Dump point: the hinge where the tip, curled (-200 deg) and opened (-70 deg), stays above the rim.
    hinge = (2.10, Y_GROUND + RIM_HEIGHT + CLEARANCE + tip_length * math.sin(math.radians(70.0)))
    phases = (
        Phase("rest at the start", 0.5, None),
        Phase(f"penetrate to {CUT_DEPTH * 1e3:.0f} mm below ground", 1.5, _pose(2.30, -CUT_DEPTH, -120.0)),
        Phase(f"drag {CUT_LENGTH:.2f} m through the soil at constant depth", 2.5, _pose(1.50, -CUT_DEPTH, -120.0)),
        Phase("curl to fill, tip out of the soil", 1.5, _pose(1.35, 0.25, -200.0)),
        Phase("lift and move to the dump point (swing loaded)", 3.0, _hinge_pose(hinge, -200.0, tip_length)),
        Phase("dump: open the bucket (curl out) over the truck", 1.5, _hinge_pose(hinge, -70.0, tip_length)),
        Phase("return to the start (swing empty)", 3.0, start),
        Phase("rest at the start", 0.5, None),
    )
    return start, phases


def grading_phases() -> tuple[Pose, tuple[Phase, ...]]:
    """Start pose and phases of the grading pass (the bucket at a fixed -135 deg: rake 45 deg)."""
    theta = -135.0
    start = _pose(2.40, 0.30, theta)
    phases = (
        Phase("rest at the start", 0.5, None),
        Phase(f"lower the tip to {GRADE_DEPTH * 1e3:.0f} mm below ground", 2.0, _pose(2.30, -GRADE_DEPTH, theta)),
        Phase(f"drag level {GRADE_LENGTH:.2f} m at a fixed attitude", 5.0, _pose(1.10, -GRADE_DEPTH, theta)),
        Phase("lift 0.3 m", 1.5, _pose(1.10, 0.30, theta)),
        Phase("return to the start", 3.0, start),
        Phase("rest at the start", 0.5, None),
    )
    return start, phases


# ---------------------------------------------------------------------------------------------
# Closed-form inverse kinematics of the 3R arm and the reach check
# ---------------------------------------------------------------------------------------------


def arm_lengths(machine: Machine) -> tuple[float, float, float]:
    """|BA|, |AL|, |LM| [m] from the machine file; refused unless the frames are the collinear 3R chain it assumes."""
    arm, bucket = machine.link("arm").joint_frame, machine.link("bucket").joint_frame
    ok = machine.joint_names == ["alpha", "beta", "gamma"] and machine.tcp_link == "bucket"
    for pose in (arm, bucket, machine.tcp):
        ok = ok and abs(pose.position[1]) < 1e-12 and np.allclose(pose.rotation, np.eye(3))
    if not ok:
        raise InvalidInputError("machine", machine.name, "the closed-form IK needs the eXact's collinear 3R frames")
    return arm.position[0], bucket.position[0], machine.tcp.position[0]


def inverse_kinematics(machine: Machine, tip: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Joints (T, 3) [rad] for tip positions (T, 2) and angles (T,); elbow down (beta < 0), as the joint ranges."""
    l1, l2, l3 = arm_lengths(machine)
    wrist = tip - l3 * np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    c = (np.sum(wrist**2, axis=-1) - l1**2 - l2**2) / (2.0 * l1 * l2)
    if np.any(np.abs(c) > 1.0):
        raise InvalidInputError("tip", f"sample {int(np.argmax(np.abs(c)))}", "beyond the arm's reach", "m")
    beta = -np.arccos(c)
    alpha = np.arctan2(wrist[:, 1], wrist[:, 0]) - np.arctan2(l2 * np.sin(beta), l1 + l2 * np.cos(beta))
    return np.stack([alpha, beta, theta - alpha - beta], axis=-1)


def joint_rates(machine: Machine, q: np.ndarray, velocity: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Joint rates (T, 3) [rad/s] from the tip velocity and the bucket's angular rate: J(q) dq = (v, omega)."""
    l1, l2, l3 = arm_lengths(machine)
    a1, a12, a123 = q[:, 0], q[:, 0] + q[:, 1], q.sum(axis=1)
    x3, y3 = l3 * np.cos(a123), l3 * np.sin(a123)
    x2, y2 = l2 * np.cos(a12) + x3, l2 * np.sin(a12) + y3
    x1, y1 = l1 * np.cos(a1) + x2, l1 * np.sin(a1) + y2
    ones = np.ones_like(a1)
    jac = np.stack([np.stack([-y1, -y2, -y3], -1), np.stack([x1, x2, x3], -1), np.stack([ones, ones, ones], -1)], 1)
    return np.linalg.solve(jac, np.column_stack([velocity, omega])[..., None])[..., 0]


def check_reach(machine: Machine, times: np.ndarray, tip: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Joints (T, 3) of every sample after checking joint ranges, strokes and the forward kinematics.

    Raises InvalidInputError naming the first time whose joint leaves its joint_range, whose
    actuator stroke leaves [0, usable stroke], or whose IK solution misses the pose.
    """
    q = inverse_kinematics(machine, tip, theta)
    for i, name in enumerate(machine.joint_names):
        low, high = machine.joint_link(name).joint_range or (-np.inf, np.inf)
        bad = (q[:, i] < low) | (q[:, i] > high)
        if np.any(bad):
            k = int(np.argmax(bad))
            raise InvalidInputError(
                f"{name} at t = {times[k]:.2f} s", float(q[k, i]), f"must lie in [{low}, {high}]", "rad"
            )
    for chain in machine.chains:
        low, high = usable_stroke(chain)
        x, _, _ = joint_to_actuator(machine, chain, q[:, machine.joint_names.index(chain.joint)], 0.0, 0.0)
        bad = ~((x >= low) & (x <= high))
        if np.any(bad):
            k = int(np.argmax(bad))
            raise InvalidInputError(
                f"{chain.name} stroke at t = {times[k]:.2f} s", float(x[k]), f"must lie in [{low}, {high}]", "m"
            )
    frames = forward_kinematics(machine, q)
    miss = np.abs(frames.tcp_position[:, :2] - tip).max()
    angle = np.arctan2(frames.tcp_rotation[:, 1, 0], frames.tcp_rotation[:, 0, 0])
    miss_angle = np.abs(np.angle(np.exp(1j * (angle - theta)))).max()
    if miss > 1e-9 or miss_angle > 1e-9:
        raise InvalidInputError("inverse kinematics", f"{miss:.3g} m, {miss_angle:.3g} rad", "must reproduce the pose")
    return q


def rod_speeds(machine: Machine, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """Actuator rod speeds (T, n_chains) [m/s]: dx = s'(q) dq for each chain."""
    cols = [
        joint_to_actuator(
            machine, c, q[:, machine.joint_names.index(c.joint)], dq[:, machine.joint_names.index(c.joint)], 0.0
        )[1]
        for c in machine.chains
    ]
    return np.column_stack(cols)


def top_rod_speed(machine: Machine) -> dict[str, float]:
    """Each chain's EMLA top rod speed [m/s]: rated speed / (2 pi G / rho) from emla_exact.yaml."""
    data = yaml.safe_load(EMLA_FILE.read_text(encoding="utf-8"))
    omega = data["pmsm"]["rated_speed_rpm"]["value"] * 2.0 * math.pi / 60.0
    out = {}
    for chain in machine.chains:
        act = data["actuators"][chain.actuator.emla]
        out[chain.name] = omega / (2.0 * math.pi * act["gear_ratio"]["value"] / act["screw_lead"]["value"])
    return out


# ---------------------------------------------------------------------------------------------
# Timing and sampling
# ---------------------------------------------------------------------------------------------


def _move(
    start: Pose, target: Pose, s: np.ndarray, ds: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    a, b = np.asarray(start), np.asarray(target)
    pose, rate = a + s[:, None] * (b - a), ds[:, None] * (b - a)
    return pose[:, :2], pose[:, 2], rate[:, :2], rate[:, 2]


def durations(machine: Machine, start: Pose, phases: tuple[Phase, ...]) -> list[float]:
    """Each phase's time [s]: the nominal one, or the time that runs the fastest rod at SPEED_SHARE of its top speed."""
    limit = top_rod_speed(machine)
    allowed = np.array([SPEED_SHARE * limit[c.name] for c in machine.chains])
    tau = np.linspace(0.0, 1.0, 2001)
    out, pose = [], start
    for phase in phases:
        if phase.target is None:
            out.append(phase.nominal)
            continue
        s, ds, _ = septic_law(tau, 0.0, 1.0)  # unit time: rod speeds scale as 1 / duration
        tip, theta, v, w = _move(pose, phase.target, s, ds)
        q = inverse_kinematics(machine, tip, theta)
        speed = np.abs(rod_speeds(machine, q, joint_rates(machine, q, v, w))).max(axis=0)
        needed = math.ceil(10.0 * float(np.max(speed / allowed)) - 1e-9) / 10.0
        out.append(max(phase.nominal, needed))
        pose = phase.target
    return out


class Task(NamedTuple):
    """A sampled task: times (T,), tip (T, 2), theta (T,) and their rates, the phases and their times."""

    name: str
    time: np.ndarray
    tip: np.ndarray
    theta: np.ndarray
    velocity: np.ndarray
    omega: np.ndarray
    phases: tuple[Phase, ...]
    times: tuple[float, ...]


def sample(machine: Machine, name: str, start: Pose, phases: tuple[Phase, ...]) -> Task:
    """Sample the task at RATE (rounded to 10 um / 10 urad) after timing its phases."""
    times = durations(machine, start, phases)
    n = round(sum(times) * RATE)
    t = np.arange(n + 1) / RATE
    tip, theta = np.empty((n + 1, 2)), np.empty(n + 1)
    v, w = np.zeros((n + 1, 2)), np.zeros(n + 1)
    pose, t0 = start, 0.0
    for phase, length in zip(phases, times, strict=True):
        inside = (t >= t0 - 1e-9) & (t <= t0 + length + 1e-9)
        target = pose if phase.target is None else phase.target
        s, ds, _ = septic_law(t[inside], t0, length)
        tip[inside], theta[inside], v[inside], w[inside] = _move(pose, target, s, ds)
        pose, t0 = target, t0 + length
    return Task(name, t, np.round(tip, 5), np.round(theta, 5), v, w, phases, tuple(times))


def render(task: Task, header: list[str]) -> str:
    """The CSV text: '#' comment lines, the column names, one row per sample."""
    lines = [f"# {line}".rstrip() for line in header]
    rows = (f"{t:.2f},{x:.5f},{y:.5f},{a:.5f}" for t, (x, y), a in zip(task.time, task.tip, task.theta, strict=True))
    return "\n".join([*lines, "t,x,y,tcp_angle", *rows]) + "\n"


def header(task: Task, lead: list[str]) -> list[str]:
    """Comment lines: what the file is, its sources (the lead), its phases and times, how to rebuild it."""
    out = [f"eXact excavator arm: {task.name} (generated by optimize/make_excavator_cycles.py; do not edit by hand)"]
    out += lead
    out.append("Phases (nominal -> used time [s]; slowed where an EMLA rod would exceed 90 % of 0.0964 m/s),")
    out.append(
        "each to its waypoint (tip x [m], tip height above ground [m], tcp_angle [deg]; choices in the workspace):"
    )
    for phase, used in zip(task.phases, task.times, strict=True):
        where = "" if phase.target is None else f" to ({phase.target[0]:.3f}, {phase.target[1] - Y_GROUND:+.3f}, "
        where += "" if phase.target is None else f"{math.degrees(phase.target[2]):.1f})"
        out.append(f"  {phase.name}: {phase.nominal:.1f} -> {used:.1f}{where}")
    out.append(f"Total {sum(p.nominal for p in task.phases):.1f} s nominal, {sum(task.times):.1f} s used.")
    out += [
        f"Ground level y = {Y_GROUND} m (read: exact_excavator.yaml notes.ground, eXactMPC yGround).",
        "Columns: t [s]; x, y: bucket tip M in the chassis frame {i} (origin at the boom hinge B, x forward,",
        "y up) [m]; tcp_angle: world angle of the bucket frame's x axis, hinge L -> tip M [rad] (alpha+beta+gamma).",
        "Moves: rest to rest, straight in (x, y, tcp_angle), septic timing; 50 Hz; every sample checked against the",
        "joint ranges and the EMLA strokes of exact_excavator.yaml with a closed-form inverse kinematics.",
        "Regenerate: python optimize/make_excavator_cycles.py",
    ]
    return out


def build(machine: Machine) -> dict[str, str]:
    """Both CSV texts by file name, after checking every sample's reach."""
    l3 = arm_lengths(machine)[2]
    dig = sample(machine, "digging cycle", *digging_phases(l3))
    grade = sample(machine, "grading pass", *grading_phases())
    cat = [
        "Cycle time: Caterpillar Performance Handbook, Edition 47 (SEBD0351-47, 2017), Cycle Time Estimating",
        "Charts, p. 7-246: load bucket, swing loaded, dump bucket, swing empty; 10 to 17 s cycles practical with",
        "the truck beside the excavator. Nominal split of a 14 s cycle (our choice): 5.5 load, 3.0 swing loaded,",
        "1.5 dump, 3.0 swing empty, 0.5 + 0.5 at rest; the swing is out of plane, in plane the arm lifts and lowers.",
        f"Cut: {CUT_DEPTH * 1e3:.0f} mm deep, {CUT_LENGTH:.2f} m long, bucket at -120 deg (rake 60 deg) (choice);",
        f"bucket width for the soil force {BUCKET_WIDTH:.2f} m (choice: the eXact source gives none).",
        f"Truck-bed height: the body's side boards {RIM_HEIGHT:.2f} m above ground (choice: no published bed height",
        "found; a 1-2 t mini excavator loads 1-ton trucks (Bobcat E20 announcement, dump height 2.69 m), whose",
        "contractor's dump bodies have 12-24 in sides (Fleet Financials); 0.8-0.9 m chassis and floor estimated);",
        f"the tip stays {CLEARANCE * 1e3:.0f} mm above them while the bucket opens from -200 to -70 deg at the",
        "dump point.",
    ]
    grading = [
        "Times: no published grading-pass time found; chosen (mean drag speed 0.24 m/s).",
        f"Drag: the tip {GRADE_DEPTH * 1e3:.0f} mm below ground over {GRADE_LENGTH:.2f} m, bucket fixed at -135 deg",
        f"(rake 45 deg from the ground, towards the machine) (choice); bucket width {BUCKET_WIDTH:.2f} m (choice).",
    ]
    out = {}
    for task, lead, file in ((dig, cat, "exact_digging_cycle.csv"), (grade, grading, "exact_grading_pass.csv")):
        check_reach(machine, task.time, task.tip, task.theta)
        out[file] = render(task, header(task, lead))
    return out


def main(out_dir: Path = HERE) -> None:
    """Write both CSVs into ``out_dir`` and print their times and peak rod speeds."""
    machine = load_machine("exact")
    if str(Y_GROUND) not in shipped("machine", "exact").read_text():
        raise InvalidInputError("Y_GROUND", Y_GROUND, "must be the ground level the machine file states")
    out_dir.mkdir(parents=True, exist_ok=True)
    for file, text in build(machine).items():
        (out_dir / file).write_text(text, encoding="utf-8")
        rows = [line for line in text.splitlines() if not line.startswith("#")][1:]
        print(f"wrote {out_dir / file}: {len(rows)} samples, {float(rows[-1].split(',')[0]):.1f} s")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE)

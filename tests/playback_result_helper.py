"""A fabricated crane result folder for the render tests and benchmark (shared test helper, not a test module).

It follows the ``hiab-sim optimize`` contract: ``result.json`` with two feasible link-length sets
and ``trajectory.npz`` with a smooth joint loop inside the working ranges, the same for both designs.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.crane.kinematics import tcp_position
from hiab_sim.crane.mechanism import check_lengths


def joint_loop(time: np.ndarray, duration: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(theta1 [rad], theta2 [rad], xt2 [m]) around (0.6, -1.3, 0.4), with exact rates and accelerations, (T, 3) each.

    One loop per ``duration`` [s] (the telescope twice); ``time`` [s], (T,).
    """
    w = 2.0 * np.pi / duration
    amp = np.array([0.25, 0.3, 0.3])
    freq = np.array([1.0, 1.0, 2.0])
    phase = np.array([0.0, 1.0, 0.0])
    arg = w * freq * time[:, None] + phase
    centre = np.array([0.6, -1.3, 0.4])
    return centre + amp * np.sin(arg), amp * w * freq * np.cos(arg), -amp * (w * freq) ** 2 * np.sin(arg)


def write_playback_result(folder: Path, crane: Crane, duration: float, samples: int, study: str) -> Path:
    """A result folder as ``hiab-sim optimize`` writes it: ``samples`` points over ``duration`` [s]; returns it.

    The initial design is the crane's default lengths, the optimal one the default with lift L x 1.03
    and Lc0 x 1.2 (both checked feasible); both follow :func:`joint_loop`.
    """
    folder.mkdir(parents=True, exist_ok=True)
    initial = crane.default_lengths
    optimal = LinkLengths.from_array(initial.as_array() * np.array([1.03, 1.2, 1.0, 1.0, 1.0, 1.0]))
    check_lengths(crane, optimal)
    time = np.linspace(0.0, duration, samples)
    p, v, a = joint_loop(time, duration)

    def lengths(xi: LinkLengths) -> dict[str, dict[str, float]]:
        return {name: {"L": c.L, "Lc0": c.Lc0, "Lc": c.Lc} for name, c in zip(("lift", "tilt"), xi, strict=True)}

    result = {"crane": "xs031", "study": study, "initial": {"lengths": lengths(initial)}}
    result["optimal"] = {"lengths": lengths(optimal)}
    (folder / "result.json").write_text(json.dumps(result))
    arrays = {"time": time, "reference_tcp": tcp_position(crane, p[:, 0], p[:, 1], p[:, 2])}
    for design in ("initial", "optimal"):
        arrays |= {f"{design}_position": p, f"{design}_velocity": v, f"{design}_acceleration": a}
    np.savez(folder / "trajectory.npz", **arrays)
    return folder

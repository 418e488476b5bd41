"""A small excavator study optimised by ``hiab-sim optimize`` (about 10 s), and the open-loop hold of a plan's start."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import yaml

from hiab_sim.cli import main
from hiab_sim.study.run import run_study
from hiab_sim.study.spec.study_file import load_study

if TYPE_CHECKING:
    from dm_control.rl import control

#: A small excavator study: three joints from one pose to another in 4 s (``move.csv``, :func:`joint_csv`), 50 kg held.
EXCAVATOR_STUDY = {
    "name": "excavator_move",
    "machine": "exact",
    "emla": "exact",
    "tasks": [{"name": "move", "weight": 1, "reference": {"kind": "csv", "file": "move.csv"}, "payload": 50.0}],
    "spline": {"control_points": 12, "degree": 5},
    "grid": {"duration": 4.0, "intervals": 12, "fine_factor": 4},
    "bounds": {"joint_velocity": [0.6, 0.6, 1.0]},
}


def joint_csv(path: Path, names: tuple[str, ...], start: list[float], end: list[float], duration: float) -> None:
    """A rest-to-rest quintic joint move (t, q...) sampled at 10 Hz."""
    t = np.linspace(0.0, duration, int(10 * duration) + 1)
    tau = t / duration
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    q = np.asarray(start)[None] + s[:, None] * (np.asarray(end) - np.asarray(start))[None]
    lines = ["# a test move", ",".join(("t", *names))]
    lines += [",".join(f"{v:.12g}" for v in row) for row in np.column_stack([t, q])]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def excavator_move(folder: Path) -> None:
    """Write the excavator study's ``move.csv`` and ``study.yaml`` into ``folder``."""
    joint_csv(folder / "move.csv", ("alpha", "beta", "gamma"), [0.0, -1.8, -1.0], [0.5, -1.3, -0.3], 4.0)
    (folder / "study.yaml").write_text(yaml.safe_dump(EXCAVATOR_STUDY), encoding="utf-8")


def solved_study(folder: Path) -> Path:
    """Optimise ``folder``'s ``study.yaml`` (no figures) into ``folder / "result"`` and return that folder."""
    out = folder / "result"
    run_study(load_study(folder / "study.yaml"), out, figures=False, progress=None)
    return out


def excavator_result(folder: Path) -> Path:
    """Write the study into ``folder``, optimise it (no video, figures or report) and return the result folder."""
    excavator_move(folder)
    run = folder / "run"
    status = main(
        [
            "optimize",
            str(folder / "study.yaml"),
            "--out",
            str(run),
            "--no-video",
            "--no-figures",
            "--no-report",
            "--quiet",
        ]
    )
    if status != 0:
        raise AssertionError(f"hiab-sim optimize exited {status}")
    return run


def held_stroke_drift(env: control.Environment, current: np.ndarray) -> float:
    """Largest stroke change [m] over 200 physics steps (0.2 s) holding the start at ``current`` [A], no feedback.

    ``env``: a machine file's closed-loop environment (:func:`hiab_sim.env.machine_env.machine_environment`),
    reset here; its physics is freed afterwards.
    """
    physics = env.physics
    env.reset()
    start = physics.stroke().copy()
    physics.holding = True
    physics.current_reference = current.copy()
    physics.step(200)
    drift = float(np.max(np.abs(physics.stroke() - start)))
    physics.free()
    return drift

"""A machine file's result folder made by ``hiab-sim optimize`` on a small excavator study (about 10 s)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from hiab_sim.cli import main

#: The excavator study of ``test_machine_study``: three joints from one pose to another in 4 s, 50 kg held.
EXCAVATOR_STUDY = {
    "name": "excavator_move",
    "machine": "exact",
    "emla": "exact",
    "tasks": [{"name": "move", "weight": 1, "reference": {"kind": "csv", "file": "move.csv"}, "payload": 50.0}],
    "spline": {"control_points": 12, "degree": 5},
    "grid": {"duration": 4.0, "intervals": 12, "fine_factor": 4},
    "bounds": {"joint_velocity": [0.6, 0.6, 1.0]},
}


def excavator_result(folder: Path) -> Path:
    """Write the study into ``folder``, optimise it (no video, figures or report) and return the result folder."""
    t = np.linspace(0.0, 4.0, 41)
    tau = t / 4.0
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)  # rest to rest (quintic)
    start, end = np.array([0.0, -1.8, -1.0]), np.array([0.5, -1.3, -0.3])
    rows = ["t,alpha,beta,gamma"] + [
        ",".join(f"{v:.12g}" for v in (ti, *(start + si * (end - start)))) for ti, si in zip(t, s, strict=True)
    ]
    (folder / "move.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    (folder / "study.yaml").write_text(yaml.safe_dump(EXCAVATOR_STUDY), encoding="utf-8")
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

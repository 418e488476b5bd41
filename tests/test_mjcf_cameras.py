"""The exported MJCF's cameras frame the machine at every pose of its working ranges, for any link lengths."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from hiab_sim.cli import main
from hiab_sim.cli.mjcf import workspace_qpos
from hiab_sim.crane.description import Crane, LinkLengths
from hiab_sim.machine_mjcf import CAMERA_ASPECT
from hiab_sim.render.camera import geom_corners


@pytest.mark.parametrize(
    ("text", "margin"),
    [("1.0071227324212,0.085,0.745,1.132185817991,0.085,0.745", "0"), ("1.25,0.3,0.735,1.24,0.3,0.637", "0.004")],
)
def test_every_camera_sees_every_geom_at_every_pose(crane: Crane, tmp_path: Path, text: str, margin: str) -> None:
    """Project each geom's bounding-box corners through MuJoCo's own camera frames: all inside the 16:9 view.

    For the crane's own lengths and for a moved design (the default study's buildable one).
    """
    out = tmp_path / "crane.xml"
    assert main(["mjcf", "--lengths", text, "--stroke-margin", margin, "-o", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    names = ["side", "perspective"]
    assert all(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, n) >= 0 for n in names)
    from hiab_sim.crane.tolerance import buildable_crane
    from hiab_sim.model.mjcf import build_model

    served = buildable_crane(crane, float(margin))
    lengths = LinkLengths.from_array([float(v) for v in text.split(",")])
    reference = build_model(served, lengths)
    joints = [reference.joint(j).name for j in range(reference.njnt)]
    address = [int(model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)]) for n in joints]
    poses = workspace_qpos(served, lengths)
    worst = 0.0
    for q in poses[:: max(1, len(poses) // 16)]:
        data.qpos[address] = q
        mujoco.mj_forward(model, data)
        corners = geom_corners(model, data)
        for name in names:
            cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, name)
            frame = data.cam_xmat[cam].reshape(3, 3)  # columns: right, up, backwards
            local = (corners - data.cam_xpos[cam]) @ frame
            depth = -local[:, 2]
            assert np.all(depth > 0.0)
            tan_y = np.tan(np.radians(model.cam_fovy[cam]) / 2.0)
            x = np.abs(local[:, 0] / depth) / (tan_y * CAMERA_ASPECT)
            y = np.abs(local[:, 1] / depth) / tan_y
            worst = max(worst, float(np.max(np.maximum(x, y))))
    assert worst <= 1.0  # every corner in view
    assert worst > 0.6  # and the machine fills the view, not a speck in the middle

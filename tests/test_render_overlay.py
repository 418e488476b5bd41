"""What the playback states and draws from the result: each design's battery energy, the payload while held.

A fabricated result folder (as :mod:`test_render` writes it) gains an ``energy`` section with
chosen battery energies and a ``payload_mass`` schedule; a real run of the tiny study with a
picked and released payload checks that ``hiab-sim optimize`` writes both.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from test_render import DURATION, SIZE, write_result
from test_study_small import TINY, small_study, write_study

from hiab_sim.crane.description import Crane
from hiab_sim.render import load_playback, playback_renderer
from hiab_sim.render.dress import PAYLOAD_RGBA, STEEL_DENSITY
from hiab_sim.render.video import energy_notes, held_payload
from hiab_sim.study.run import run_study
from hiab_sim.study.spec.study_file import load_study

#: Battery energies written into the fabricated result [J]: values no computation here would give.
BATTERY = {"initial": 7243.5, "optimal": 7106.25}
#: The fabricated payload: 150 kg held for PICK <= t < RELEASE [s].
MASS, PICK, RELEASE = 150.0, 0.3, 0.7


def _with_energy_and_payload(folder: Path, crane: Crane) -> Path:
    write_result(folder, crane)
    result = json.loads((folder / "result.json").read_text())
    result["energy"] = {name: {"battery_energy_J": value, "costf2_W2s": 1.0} for name, value in BATTERY.items()}
    (folder / "result.json").write_text(json.dumps(result))
    with np.load(folder / "trajectory.npz") as npz:
        arrays = {key: npz[key] for key in npz.files}
    time = arrays["time"]
    arrays["payload_mass"] = np.where((time >= PICK) & (time < RELEASE), MASS, 0.0)
    np.savez(folder / "trajectory.npz", **arrays)
    return folder


@pytest.fixture(scope="module")
def loaded(tmp_path_factory: pytest.TempPathFactory, crane: Crane) -> Path:
    return _with_energy_and_payload(tmp_path_factory.mktemp("overlay") / "result", crane)


@pytest.mark.sim
def test_overlay_states_each_designs_battery_energy_from_the_result(loaded: Path) -> None:
    """Every frame's note names the battery energy of result.json with its boundary, per design."""
    with playback_renderer(load_playback(loaded), fps=12.0, size=SIZE, layout="overlay") as renderer:
        for design in renderer.designs:
            want = f"battery energy {BATTERY[design.name] / 1e3:.3f} kJ per cycle (at the battery)"
            assert design.notes and all(want in note for note in design.notes)


def test_a_result_without_a_battery_figure_says_what_it_shows() -> None:
    """No battery figure: the note names the drives' net electrical energy; no power either: it says so."""
    time = np.linspace(0.0, 2.0, 9)
    notes = energy_notes(time, np.array([0.0, 2.0]), np.full(9, 1000.0))
    assert notes[-1].endswith("drives' net electrical energy 2.000 of 2.000 kJ (no battery figure)")
    assert "no energy figure" in energy_notes(time, np.array([0.5]), None)[0]
    assert energy_notes(time, np.array([0.5]), None, 3000.0, "duty period")[0].endswith(
        "battery energy 3.000 kJ per duty period (at the battery)"
    )


def _payload_boxes(scene: Any) -> list[np.ndarray]:
    """Half sizes of the scene's payload boxes (box geoms in the payload's colour) of an ``mujoco.MjvScene``."""
    import mujoco  # after hiab_sim.render chose the OpenGL backend (MuJoCo reads it once, at import)

    found = []
    for k in range(scene.ngeom):
        geom = scene.geoms[k]
        if geom.type == mujoco.mjtGeom.mjGEOM_BOX and np.allclose(geom.rgba[:3], PAYLOAD_RGBA[:3], atol=1e-6):
            found.append(np.array(geom.size))
    return found


@pytest.mark.sim
def test_payload_is_in_the_scene_only_while_held(loaded: Path) -> None:
    """Frames before the pick and after the release have no payload box; frames between have one.

    Both designs hold it at the same tool point (the link lengths move the cylinders only), so the
    ghost's copy coincides with the opaque design's and is not drawn twice. Its side is that of a
    steel cube of the payload's mass: (m / rho)^(1/3).
    """
    fps = 20.0
    with playback_renderer(load_playback(loaded), fps=fps, size=SIZE, layout="overlay") as renderer:
        scene = renderer._renderers[0].scene
        for index in range(len(renderer)):
            t = index / fps
            if min(abs(t - PICK), abs(t - RELEASE)) < 0.02:
                continue  # the step shows to within one sample of the fine grid
            renderer.frame(index)
            boxes = _payload_boxes(scene)
            if PICK < t < RELEASE:
                assert len(boxes) == 1, t
                assert all(design.payload_at(index) == MASS for design in renderer.designs)
                side = (MASS / STEEL_DENSITY) ** (1.0 / 3.0)
                np.testing.assert_allclose(boxes[0], 0.5 * side, rtol=1e-6)
            else:
                assert boxes == [], t
        assert t == pytest.approx(DURATION)


@pytest.mark.sim
def test_a_run_writes_the_payload_schedule_and_the_battery_energy(tmp_path: Path) -> None:
    """``hiab-sim optimize``'s folder gives the video the held mass at each frame and the result's battery energy."""
    payload = {"mass": 150.0, "pick": 1.0, "release": 5.0}
    study = load_study(write_study(tmp_path, small_study(**TINY, payload=payload)))
    output = run_study(study, tmp_path / "run", progress=None, figures=False)
    data = load_playback(output.folder)
    assert output.result.energy is not None
    assert data.battery_energy_J == {
        "initial": output.result.energy.initial.battery_energy_J,
        "optimal": output.result.energy.optimal.battery_energy_J,
    }
    step = float(data.time[1] - data.time[0])
    at = np.array([0.0, 1.0 - 1.5 * step, 1.0 + 1.5 * step, 3.0, 5.0 - 1.5 * step, 5.0 + 1.5 * step, 6.0])
    assert held_payload(data, at) == (0.0, 0.0, 150.0, 150.0, 150.0, 0.0, 0.0)

"""A machine file's playback dressed from its description: the eXact excavator on a fabricated motion.

The playback is built in memory (seconds, no optimisation): the shipped eXact arm moving rest to
rest through its working ranges for 4 s, two designs that differ in the bucket linkage's base pin,
a 76 kg payload held from 1 s to 3 s, battery energies chosen here and the digging study's ground
level. Renders through the OpenGL backend hiab_sim selects (OSMesa on CI, MUJOCO_GL=osmesa).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_render import _luminance, _project, _saturated

from hiab_sim.machine.description import Machine
from hiab_sim.machine.kinematics.forward import forward_kinematics
from hiab_sim.machine.loader import load_machine
from hiab_sim.model.mjcf import SOURCE_TO_WORLD
from hiab_sim.render.dress import PAYLOAD_RGBA, PIN_RGBA
from hiab_sim.render.dress_machine import (
    SLENDERNESS,
    SOIL_DENSITY,
    machine_file_dress,
    moved_pivots,
    section_depth,
)
from hiab_sim.render.machine_playback import MachineMotion, MachinePlayback, machine_model_and_qpos
from hiab_sim.render.machine_video import machine_renderer

#: Battery energies [J] and the payload (kg, held for PICK <= t < RELEASE s): values no computation here gives.
BATTERY = {"initial": 8656.0, "optimal": 8401.0}
MASS, PICK, RELEASE = 76.0, 1.0, 3.0
#: The digging study's ground level [m] (optimize/exact_digging.yaml soil.ground).
GROUND = -0.95737
SIZE = (640, 480)


@pytest.fixture(scope="module")
def machine() -> Machine:
    return load_machine("exact")


@pytest.fixture(scope="module")
def playback(machine: Machine) -> MachinePlayback:
    """Rest to rest (quintic) from one pose to another in 4 s; the optimal design moves the bucket's base pin G."""
    time = np.linspace(0.0, 4.0, 41)
    tau = time / 4.0
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    start, end = np.array([0.0, -1.8, -1.0]), np.array([0.5, -1.3, -0.3])
    q = start + s[:, None] * (end - start)
    initial = machine.design_values()
    optimal = initial.copy()
    keys = machine.variable_keys
    optimal[keys.index("bucket.Gx")], optimal[keys.index("bucket.Gy")] = -0.039, 0.354
    tcp = forward_kinematics(machine, q).tcp_position
    payload = np.where((time >= PICK) & (time < RELEASE), MASS, 0.0)
    motions = (MachineMotion("initial", initial, q, None), MachineMotion("optimal", optimal, q, None))
    return MachinePlayback(machine, time, tcp, motions, payload, BATTERY, "cycle", GROUND)


@pytest.mark.sim
def test_dressed_excavator_frame_spans_the_machine_and_its_captions_read(playback: MachinePlayback) -> None:
    """A 640x480 overlay frame shows the whole arm, its pins, the payload in the bucket and readable captions.

    The design-coloured pixels reach from the boom hinge to the bucket tip as an independent pinhole
    model projects them; every hinge and every loop-closing pin is drawn; the captions name each
    design's battery energy and their text has a contrast ratio above 4.5 (WCAG AA) on its box.
    """
    at = np.array([2.0])  # the payload is held
    with machine_renderer(playback, size=SIZE, layout="overlay", at=at) as renderer:
        image = renderer.frame(0)
        optimal = renderer.designs[0]
        fovy = float(optimal.model.vis.global_.fovy)
        tool = _project(renderer.camera, optimal.tcp[0], SIZE, fovy)
        hinge = _project(renderer.camera, np.zeros(3), SIZE, fovy)
        caption_rows = sum(c.shape[0] + 6 for c in renderer._captions) + 2 * (renderer._line + 6)
        scene = renderer._renderers[0].scene
        colours = [np.array(scene.geoms[k].rgba[:3]) for k in range(scene.ngeom)]
        alphas = [float(scene.geoms[k].rgba[3]) for k in range(scene.ngeom)]
        pins = [a for c, a in zip(colours, alphas, strict=True) if np.allclose(c, PIN_RGBA[:3], atol=1e-6)]
        loads = sum(np.allclose(c, PAYLOAD_RGBA[:3], atol=1e-6) for c in colours)
        model = optimal.model
        notes = [d.notes[0] for d in renderer.designs]
    hinges = int(np.sum(model.jnt_type == 3))  # mjJNT_HINGE
    assert sum(a == 1.0 for a in pins) == hinges + model.neq  # every hinge and every loop's pin
    assert sum(a < 1.0 for a in pins) == hinges + model.neq  # the ghost's, set back behind the opaque ones
    assert loads == 1  # both designs hold it at the same tip: the ghost's copy is not drawn twice
    for name, note in zip(("optimal", "initial"), notes, strict=True):
        assert f"battery energy {BATTERY[name] / 1e3:.3f} kJ per cycle" in note
    arm = _saturated(image)
    arm[:caption_rows] = False  # the captions are coloured too
    rows, cols = np.nonzero(arm)
    assert cols.max() - cols.min() > 0.3 * SIZE[0] and rows.max() - rows.min() > 0.25 * SIZE[1]
    margin = 30  # px: box sections, the bucket's plates and its payload reach past the points projected
    assert cols.min() - margin <= min(tool[0], hinge[0]) and max(tool[0], hinge[0]) <= cols.max() + margin
    assert rows.min() - margin <= min(tool[1], hinge[1]) and max(tool[1], hinge[1]) <= rows.max() + margin
    assert all(0 <= p[0] < SIZE[0] and caption_rows <= p[1] < SIZE[1] for p in (tool, hinge))
    band = image[4 : renderer._captions[0].shape[0] + 8, : SIZE[0] // 2]
    lum = _luminance(band)
    text, box = np.percentile(lum, 2), np.percentile(lum, 90)
    assert (box + 0.05) / (text + 0.05) > 4.5


@pytest.mark.sim
def test_ground_and_base_stand_at_the_studys_ground_level(playback: MachinePlayback, machine: Machine) -> None:
    """The base block's bottom and the ground slab's top are the ground level; the base reaches up to the chassis."""
    model, _ = machine_model_and_qpos(machine, playback.designs[0].position[:1])
    base, soil = machine_file_dress(model, machine, GROUND).slabs
    assert base.centre[2] - base.half[2] == pytest.approx(GROUND, abs=1e-12)
    assert soil.centre[2] + soil.half[2] == pytest.approx(GROUND, abs=1e-12)
    lowest_pivot = min(p.position[1] for c in machine.chains for p in c.pivots if p.link == "chassis")
    assert GROUND < base.centre[2] + base.half[2] < lowest_pivot
    assert soil.centre[1] - soil.half[1] > 0.0  # a section through the soil behind the plane of motion


def test_box_depth_carries_the_links_mass() -> None:
    """A square tube of the drawn depth and wall depth / SLENDERNESS, rasterised, weighs the link's mass per length."""
    mass, length = 227.343, 2.05  # the eXact boom [kg] and its hinge-to-hinge length [m]
    depth = section_depth(mass, length)
    cells = 4000
    x = (np.arange(cells) + 0.5) / cells * depth
    inner = (x > depth / SLENDERNESS) & (x < depth - depth / SLENDERNESS)
    solid = ~(inner[:, None] & inner[None, :])
    area = solid.sum() * (depth / cells) ** 2
    assert area * 7850.0 * length == pytest.approx(mass, rel=1e-3)


def test_actuator_radii_come_from_the_cylinder_data_or_the_bodies(machine: Machine) -> None:
    """With the file's hydraulic cylinders, barrel = bore / 2 + wall and rod = rod / 2; without, the bodies' radii.

    The eXact file states its EMLA bodies as uniform cylinders of radius 0.06 m and rods of 0.025 m.
    """
    model, _ = machine_model_and_qpos(machine, np.array([[0.0, -1.8, -1.0]]))
    dress = machine_file_dress(model, machine, GROUND)
    barrels = sorted(r for g, r in dress.radius.items() if dress.kind[g] == "barrel")
    rods = sorted(r for g, r in dress.radius.items() if dress.kind[g] == "rod")
    np.testing.assert_allclose(barrels, [0.0275 + 0.012, 0.0325 + 0.012, 0.035 + 0.012], atol=1e-12)
    np.testing.assert_allclose(rods, [0.0175, 0.0175, 0.020], atol=1e-12)
    chains = tuple(replace(c, actuator=replace(c.actuator, hydraulic_cylinder=None)) for c in machine.chains)
    bare = replace(machine, chains=chains, hydraulic=None)
    dress = machine_file_dress(model, bare, GROUND)
    for g, r in dress.radius.items():
        assert r == pytest.approx(0.06 if dress.kind[g] == "barrel" else 0.025, rel=1e-9)


@pytest.mark.sim
def test_payload_sits_in_the_bucket_at_its_centre_of_mass(playback: MachinePlayback, machine: Machine) -> None:
    """The payload cube (soil, side (m / rho)^(1/3)) is centred at the bucket's centre of mass (kinematics)."""
    from hiab_sim.render.dress import payload_box

    with machine_renderer(playback, size=(160, 120), layout="overlay", at=np.array([2.0])) as renderer:
        optimal = renderer.designs[0]
        renderer.frame(0)
        centre, half, _ = payload_box(renderer._data[0], optimal.dress, MASS)  # type: ignore[arg-type]
    motion = playback.designs[1]
    q = np.array([np.interp(2.0, playback.time, motion.position[:, k]) for k in range(3)])
    built = machine.with_design(motion.design)
    com = forward_kinematics(built, q).point("bucket", built.link("bucket").body.com)  # type: ignore[union-attr]
    np.testing.assert_allclose(centre, SOURCE_TO_WORLD @ com, atol=1e-9)
    np.testing.assert_allclose(2.0 * half, (MASS / SOIL_DENSITY) ** (1.0 / 3.0), rtol=1e-12)


def test_marks_are_the_pivots_the_design_moves(machine: Machine) -> None:
    """Moving the bucket's base pin G marks that chain's cylinder hinge only; moving the boom's L marks the boom's."""
    initial = machine.design_values()
    keys = machine.variable_keys
    moved = initial.copy()
    moved[keys.index("bucket.Gy")] += 0.05
    assert moved_pivots(machine, [initial, moved]) == ("bucket.cylinder",)
    moved[keys.index("boom.L")] += 0.02
    assert moved_pivots(machine, [initial, moved]) == ("boom.cylinder", "bucket.cylinder")
    rods = initial.copy()
    rods[keys.index("arm.Lc")] += 0.02  # a rod length moves no pivot
    assert moved_pivots(machine, [initial, rods]) == ()


def test_a_link_whose_mass_lies_off_its_chord_is_drawn_bent_through_its_knee(machine: Machine) -> None:
    """The eXact boom (mass 0.38 m off B->A) bends through the arm cylinder's base pin E; the arm is straight."""
    from hiab_sim.render.dress_machine import spine

    boom, arm = machine.link("boom"), machine.link("arm")
    carried = [np.asarray(p.position, dtype=float) for c in machine.chains for p in c.pivots if p.link == "boom"]
    to_arm = np.asarray(arm.joint_frame.position, dtype=float)
    line = spine(to_arm, carried, np.asarray(boom.body.com), 0.27)  # type: ignore[union-attr]
    np.testing.assert_allclose(line[1], machine.chain("arm").pivot("base").position)
    to_bucket = np.asarray(machine.link("bucket").joint_frame.position, dtype=float)
    carried = [np.asarray(p.position, dtype=float) for c in machine.chains for p in c.pivots if p.link == "arm"]
    assert len(spine(to_bucket, carried, np.asarray(arm.body.com), 0.29)) == 2  # type: ignore[union-attr]


def test_excavator_page_shows_the_three_committed_frames() -> None:
    """docs/results/excavator.md embeds the start, middle and end frames that docs_figures.sh writes, each committed."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    page = (root / "docs" / "results" / "excavator.md").read_text(encoding="utf-8")
    script = (root / "scripts" / "docs_figures.sh").read_text(encoding="utf-8")
    for which in ("start", "middle", "end"):
        name = f"excavator_{which}.png"
        assert f"](../figures/{name})" in page and f'"$OUT/{name}"' in script, name
        assert (root / "docs" / "figures" / name).is_file(), name

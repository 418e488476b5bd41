"""Frames of one or two crane designs moving through qpos sequences, rendered off-screen.

A :class:`PlaybackRenderer` draws each :class:`Design` either side by side or stacked (one
viewport each; stacked suits a crane whose motion is wider than tall) or overlaid in one
viewport (the later designs as translucent ghosts showing only the parts that differ), with the
reference TCP curve and each design's TCP trail as line geoms, the design's name as a caption
and, if given, a per-frame note under it (time, battery energy). One free camera, fitted once
to the whole motion of all designs (:func:`~hiab_sim.render.camera.fit_camera`), looks onto the
crane's x-z plane of motion.

Visuals are chosen for CPU rendering through OSMesa (:func:`~hiab_sim.render.decor.set_fast_visuals`):
no shadows, reflections, skybox or multisampling; a self-lit backdrop instead of a sky.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import mujoco
import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.errors import InvalidInputError
from hiab_sim.render import decor
from hiab_sim.render.backend import open_renderer
from hiab_sim.render.camera import camera_axes, fit_camera, geom_corners
from hiab_sim.render.dress import PLANE_NORMAL, MachineDress, dress_points, dress_scene
from hiab_sim.render.labels import caption_bitmap, stamp

Image = NDArray[np.uint8]
Layout = Literal["side-by-side", "stacked", "overlay"]
LAYOUTS: tuple[str, ...] = ("side-by-side", "stacked", "overlay")
GHOST_ALPHA = 0.4
#: Radius of the balls that mark moved pivots [m].
MARK_RADIUS_M = 0.07
#: Room kept free above the machine for the captions, as a fraction of the motion's height.
CAPTION_ROOM = 0.35


def text_colour(rgba: Sequence[float]) -> tuple[float, float, float]:
    """A design's colour darkened for text on the light caption box (contrast ratio above 4.5)."""
    return (0.55 * rgba[0], 0.55 * rgba[1], 0.55 * rgba[2])


@dataclass(frozen=True)
class Design:
    """One crane design to play back: its model, qpos per frame (N, nq), colour and caption.

    The renderer adjusts the model's render settings (:func:`~hiab_sim.render.decor.prepare_model`),
    so pass a model built for rendering.
    """

    name: str
    model: mujoco.MjModel
    qpos: Array
    rgba: tuple[float, float, float, float]
    caption: str | None = None  # top-left of the design's viewport; default: the name
    notes: tuple[str, ...] = ()  # one text per frame under the caption (time, energy); () for none
    tcp_site: str = "tcp"
    #: The machine's dressing (box booms, cylinders of the data, pins, blocks, hook, bed); None: the bare model.
    dress: MachineDress | None = None
    #: Sites (or bodies, at their origin) marked with a ball of the design's colour (pivots that move between designs).
    marks: tuple[str, ...] = ()
    #: Payload mass held at the TCP per frame [kg] (0 while not held), drawn with the dressing; () for none.
    payload: tuple[float, ...] = ()
    #: TCP position per frame (N, 3) in the MuJoCo world [m], computed from ``qpos``.
    tcp: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        qpos = np.asarray(self.qpos, dtype=float)
        if qpos.ndim != 2 or qpos.shape[1] != self.model.nq or len(qpos) == 0:
            raise InvalidInputError(
                f"{self.name}.qpos", f"shape {qpos.shape}", f"must have shape (N >= 1, nq = {self.model.nq})"
            )
        site = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, self.tcp_site)
        if site < 0:
            raise InvalidInputError(f"{self.name}.tcp_site", self.tcp_site, "must name a site of the model")
        data = mujoco.MjData(self.model)
        tcp = np.empty((len(qpos), 3))
        for k, q in enumerate(qpos):
            data.qpos[:] = q
            mujoco.mj_kinematics(self.model, data)
            tcp[k] = data.site_xpos[site]
        if self.notes and len(self.notes) != len(qpos):
            raise InvalidInputError(
                f"{self.name}.notes", len(self.notes), f"must hold one text per frame ({len(qpos)})"
            )
        if self.payload and len(self.payload) != len(qpos):
            raise InvalidInputError(
                f"{self.name}.payload", len(self.payload), f"must hold one mass per frame ({len(qpos)})"
            )
        object.__setattr__(self, "qpos", qpos)
        object.__setattr__(self, "tcp", tcp)

    def __len__(self) -> int:
        return int(self.qpos.shape[0])

    def payload_at(self, index: int) -> float:
        """Payload mass held at frame ``index`` [kg] (0 without a payload)."""
        return float(self.payload[index]) if self.payload else 0.0


def _dress_geoms(design: Design) -> int:
    """Most scene geoms a design adds beyond its model's: pins, hook, payload, blocks, plates, slabs, marks."""
    dress = design.dress
    parts = 0 if dress is None else len(dress.blocks) + len(dress.plates) + len(dress.slabs)
    return design.model.njnt + design.model.neq + 4 + parts + len(design.marks)


class PlaybackRenderer:
    """Render frames of one or more designs; a context manager that frees its OpenGL contexts.

    Args:
        designs: the designs, all with the same number of frames (side by side: left to right;
            stacked: top to bottom; overlaid: the first opaque, the others translucent).
        reference: the reference TCP curve (M, 3) in the MuJoCo world [m], or None.
        size: image (width, height) [px]; side by side each design gets width / len(designs),
            stacked height / len(designs).
        layout: ``"side-by-side"``, ``"stacked"`` or ``"overlay"``.
        shadows: draw shadows and reflections (several times slower on CPU; for comparison).

    """

    def __init__(
        self,
        designs: Sequence[Design],
        reference: Array | None = None,
        size: tuple[int, int] = (640, 480),
        layout: Layout = "side-by-side",
        shadows: bool = False,
    ) -> None:
        if not designs:
            raise InvalidInputError("designs", "[]", "at least one design is needed")
        if layout not in LAYOUTS:
            raise InvalidInputError("layout", layout, f"must be one of {', '.join(LAYOUTS)}")
        if len({len(d) for d in designs}) != 1:
            raise InvalidInputError("designs", [len(d) for d in designs], "must all have the same number of frames")
        width, height = size
        panels = 1 if layout == "overlay" else len(designs)
        along, side = (height, "height") if layout == "stacked" else (width, "width")
        if along % panels or along < 16 * panels or min(width, height) < 16:
            raise InvalidInputError("size", f"{width}x{height}", f"{side} must split into {panels} panels >= 16 px")
        self.designs = tuple(designs)
        self.reference = None if reference is None else np.asarray(reference, dtype=float).reshape(-1, 3)
        self.size = (width, height)
        self.layout = layout
        self._data = [mujoco.MjData(d.model) for d in self.designs]
        self._option = mujoco.MjvOption()
        self._perturb = mujoco.MjvPerturb()
        panel_width = width // panels if layout == "side-by-side" else width
        panel_height = height // panels if layout == "stacked" else height
        extra = sum(_dress_geoms(d) for d in self.designs)
        max_geom = sum(d.model.ngeom for d in self.designs) + decor.MAX_SEGMENTS * (len(self.designs) + 1) + 16 + extra
        self._renderers: list[mujoco.Renderer] = []
        try:
            for design in self.designs if layout != "overlay" else self.designs[:1]:
                decor.prepare_model(design.model)
                renderer = open_renderer(design.model, panel_width, panel_height, max_geom=max_geom)
                decor.set_fast_visuals(renderer.scene, shadows)
                self._renderers.append(renderer)
        except BaseException:
            self.close()
            raise
        points = self._motion_points()
        low, high = points.min(axis=0), points.max(axis=0)
        room = 0.5 * (low + high) + [0.0, 0.0, 0.5 * (high[2] - low[2]) * (1.0 + 2.0 * CAPTION_ROOM)]
        points = np.vstack([points, room])  # the captions' band stays clear of the machine
        fovy = float(self.designs[0].model.vis.global_.fovy)
        self.camera = fit_camera(points, aspect=panel_width / panel_height, fovy=fovy)
        forward, _, _ = camera_axes(float(self.camera.azimuth), float(self.camera.elevation))
        depth = float(np.max((points - self.camera.lookat) @ forward)) + 1.0
        aspect = panel_width / panel_height
        self._backdrop = (depth, 4.0 * (self.camera.distance + depth) * np.tan(np.radians(fovy)) * max(aspect, 1.0))
        # a ghost's part within this of the opaque one's (1.5 px in the plane of motion) is not drawn: it would flicker
        self._same_m = 1.5 * 2.0 * self.camera.distance * np.tan(np.radians(fovy) / 2.0) / panel_height
        self._line = max(16, min(panel_height // 14 if layout == "stacked" else height // 20, panel_width // 28))
        self._captions = [caption_bitmap(d.caption or d.name, text_colour(d.rgba), self._line) for d in self.designs]

    def __len__(self) -> int:
        return len(self.designs[0])

    def _motion_points(self, samples: int = 40) -> Array:
        """Geom bounding-box corners of every design over ``samples`` frames, and the reference."""
        points = [] if self.reference is None else [self.reference]
        for design, data in zip(self.designs, self._data, strict=True):
            for k in np.unique(np.linspace(0, len(design) - 1, samples).round().astype(int)):
                data.qpos[:] = design.qpos[k]
                mujoco.mj_kinematics(design.model, data)
                points.append(geom_corners(design.model, data))
                if design.dress is not None:
                    points.append(dress_points(design.model, data, design.dress, max(design.payload, default=0.0)))
            points.append(design.tcp)
        return np.concatenate(points)

    def _decorate(self, scene: mujoco.MjvScene, designs: Sequence[Design], index: int) -> None:
        decor.add_backdrop(scene, self.camera, *self._backdrop)
        if self.reference is not None:
            decor.add_polyline(scene, self.reference, decor.REFERENCE_RGBA, width=decor.LINE_WIDTH - 1.0)
        for design in designs:
            decor.add_polyline(scene, design.tcp[: index + 1], design.rgba)
        self._marks(scene, designs)

    def _marks(self, scene: mujoco.MjvScene, designs: Sequence[Design]) -> None:
        """A ball of each design's colour at its marked sites and bodies; overlaid, a line to the next design's."""
        where: list[dict[str, Array]] = []
        for design in designs:
            data = self._data[self.designs.index(design)]
            found = {}
            for name in design.marks:
                site = mujoco.mj_name2id(design.model, mujoco.mjtObj.mjOBJ_SITE, name)
                body = mujoco.mj_name2id(design.model, mujoco.mjtObj.mjOBJ_BODY, name)
                if site >= 0 or body >= 0:
                    found[name] = np.array(data.site_xpos[site] if site >= 0 else data.xpos[body])
                    if design.dress is not None:  # on the pin's end facing the camera, not inside the section
                        found[name] -= PLANE_NORMAL * 0.5 * design.dress.pin_length
                    decor.add_ball(scene, found[name], MARK_RADIUS_M, design.rgba)
            where.append(found)
        for first, second in itertools.pairwise(where):
            for name in first.keys() & second.keys():
                decor.add_polyline(scene, np.stack([first[name], second[name]]), (0.1, 0.1, 0.1, 1.0), width=2.0)

    def frame(self, index: int) -> Image:
        """The RGB image (height, width, 3) uint8 of frame ``index``."""
        if not 0 <= index < len(self):
            raise InvalidInputError("frame index", index, f"must lie in [0, {len(self) - 1}]")
        for design, data in zip(self.designs, self._data, strict=True):
            data.qpos[:] = design.qpos[index]
            mujoco.mj_kinematics(design.model, data)
        if self.layout == "overlay":
            return self._overlay_frame(index)
        images = []
        for renderer, design, data, caption in zip(
            self._renderers, self.designs, self._data, self._captions, strict=True
        ):
            renderer.update_scene(data, camera=self.camera, scene_option=self._option)
            if design.dress is not None:
                dress_scene(
                    renderer.scene, (0, renderer.scene.ngeom), design.model, data, design.dress, design.rgba,
                    payload_kg=design.payload_at(index),
                )  # fmt: skip
            else:
                decor.tint_geoms(renderer.scene, 0, design.rgba)
            self._decorate(renderer.scene, [design], index)
            image = renderer.render()
            self._label(image, design, caption, index, top=8)
            images.append(image)
        return np.concatenate(images, axis=0 if self.layout == "stacked" else 1)

    def _label(self, image: Image, design: Design, caption: NDArray[np.float32], index: int, top: int) -> int:
        """Stamp the caption and the frame's note of a design from ``top`` [px]; return the next free row."""
        stamp(image, caption, top=top)
        top += caption.shape[0] + 6
        if design.notes:
            note = caption_bitmap(design.notes[index], text_colour(design.rgba), max(14, int(0.8 * self._line)))
            stamp(image, note, top=top)
            top += note.shape[0] + 6
        return top

    def _overlay_frame(self, index: int) -> Image:
        renderer = self._renderers[0]
        renderer.update_scene(self._data[0], camera=self.camera, scene_option=self._option)
        scene = renderer.scene
        if self.designs[0].dress is None:
            decor.tint_geoms(scene, 0, self.designs[0].rgba)
        spans = [(0, scene.ngeom)]
        for design, data in zip(self.designs[1:], self._data[1:], strict=True):
            start = scene.ngeom
            mujoco.mjv_addGeoms(design.model, data, self._option, self._perturb, mujoco.mjtCatBit.mjCAT_DYNAMIC, scene)
            decor.drop_coincident(scene, start, self._same_m)
            spans.append((start, scene.ngeom))
        for k, (design, data, span) in enumerate(zip(self.designs, self._data, spans, strict=True)):
            if design.dress is not None:
                alpha = 1.0 if k == 0 else GHOST_ALPHA
                start = scene.ngeom
                dress_scene(
                    scene, span, design.model, data, design.dress, design.rgba, alpha, ground=k == 0,
                    payload_kg=design.payload_at(index),
                )  # fmt: skip
                if k > 0:  # the ghost's pins, plates and blocks where the opaque design has them already
                    decor.drop_coincident(scene, start, self._same_m)
            elif k > 0:
                decor.tint_geoms(scene, span[0], (*design.rgba[:3], GHOST_ALPHA), weight=0.8)
        self._decorate(scene, self.designs, index)
        image = renderer.render()
        top = 8
        for design, caption in zip(self.designs, self._captions, strict=True):
            top = self._label(image, design, caption, index, top)
        return image

    def close(self) -> None:
        """Free the OpenGL contexts (idempotent); left to the garbage collector, OSMesa may complain at exit."""
        for renderer in self._renderers:
            renderer.close()
        self._renderers = []

    def __enter__(self) -> PlaybackRenderer:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

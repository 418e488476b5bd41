"""``render_result``: a playback video (or a still frame) of an optimisation result folder.

Each design is named and shows, per frame, the time and its battery energy per cycle (per duty
period with the study's duty model) [kJ], the quantity the answer is stated in, read from
``result.json``'s ``energy`` section: the energy the battery delivers through the shared DC bus,
regeneration credited (:mod:`hiab_sim.emla.battery`). A result without a battery figure shows
instead, named as such, the drives' cumulative net electrical energy E(t) = integral of sum_i
P_elec,i dt [kJ] (trapezoidal on the result's fine grid, whose total is the result's
``net_electrical_energy_J``) next to its total. The machine is dressed from its description
(:mod:`hiab_sim.render.dress`) in the colours of :mod:`hiab_sim.style`, with the task's payload
under the hook while it is held (``trajectory.npz``'s ``payload_mass``). The default layout overlays
the initial design as a ghost on the optimal one, with the cylinder base pivots that the link
lengths move marked by balls of each design's colour and joined by a line.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import numpy as np

from hiab_sim.arrays import Array
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.model.mjcf import build_model, source_to_world
from hiab_sim.render.backend import check_output_path, ffmpeg_path, still_time, write_image, write_video
from hiab_sim.render.decor import design_rgba
from hiab_sim.render.dress import machine_dress
from hiab_sim.render.frames import LAYOUTS, Design, Layout, PlaybackRenderer
from hiab_sim.render.playback import (
    MODES,
    Mode,
    PlaybackData,
    frame_times,
    load_playback,
    planned_qpos,
    resample,
    simulated_qpos,
)
from hiab_sim.results.trajectory_file import read_trajectory

#: Default file name of the playback video inside a result folder.
VIDEO_NAME = "playback.mp4"
#: Default arrangement of the designs.
DEFAULT_LAYOUT: Layout = "overlay"  # the optimal design opaque, the initial one as a ghost: the difference shows


def playback_renderer(
    data: PlaybackData,
    fps: float = 30.0,
    size: tuple[int, int] = (640, 480),
    mode: Mode = "kinematic",
    layout: Layout = "side-by-side",
    shadows: bool = False,
    energy: dict[str, Array] | None = None,
) -> PlaybackRenderer:
    """A :class:`~hiab_sim.render.scene.PlaybackRenderer` of both designs of ``data`` at ``fps``.

    Side by side, the initial design is on the left (stacked: on top); overlaid, the initial
    design is drawn translucent over the optimal one. Each design's frames show the time and its
    battery energy of the result (``data.battery_energy_J``); without one, ``energy`` (a design
    name -> its net electrical power summed over the actuators at ``data.time`` [W]) gives the
    drives' cumulative net energy instead (:func:`energy_notes`). ``data.payload_mass`` is drawn
    while held (:func:`held_payload`).
    """
    if mode not in MODES:
        raise InvalidInputError("mode", mode, f"must be one of {', '.join(MODES)}")
    if layout not in LAYOUTS:
        raise InvalidInputError("layout", layout, f"must be one of {', '.join(LAYOUTS)}")
    at = frame_times(data.time, fps)
    marks = tuple(f"{chain.name}_base_pivot" for chain in data.crane.chains)  # the pivots the lengths move
    designs = []
    for motion in data.designs:
        model = build_model(data.crane, motion.lengths)
        if mode == "kinematic":
            qpos = planned_qpos(data.crane, motion.lengths, resample(data.time, motion.joints.position, at))
        else:
            qpos = resample(*simulated_qpos(data.crane, motion.lengths, data.time, motion.joints), at)
        power = None if energy is None else energy.get(motion.name)
        suffix = " (simulated)" if mode != "kinematic" else ""
        caption, notes = design_texts(motion.name, layout, data, at, power, suffix)
        designs.append(
            Design(
                motion.name, model, qpos, design_rgba(motion.name), caption, notes,
                dress=machine_dress(model, data.crane), marks=marks, payload=held_payload(data, at),
            )
        )  # fmt: skip
    if layout == "overlay":
        designs.reverse()  # the optimal design opaque, the initial one as a translucent ghost
    return PlaybackRenderer(designs, source_to_world(data.reference_tcp), size, layout=layout, shadows=shadows)


class HeldPayload(Protocol):
    """What :func:`held_payload` reads of a playback: sample times [s] and the payload mass held [kg]."""

    @property
    def time(self) -> Array:
        """Sample times (K,) [s], increasing."""
        ...

    @property
    def payload_mass(self) -> Array | None:
        """Payload mass held at each sample (K,) [kg]; None without a payload."""
        ...


def held_payload(data: HeldPayload, at: Array) -> tuple[float, ...]:
    """The payload mass held at each frame instant ``at`` [kg]; () when the result has none.

    The schedule is a step (:class:`hiab_sim.study.spec.payload.Payload`: held for pick <= t <
    release), so each frame takes the value of the last sample at or before it, never a blend; the
    pick and release show to within one step of the result's fine grid.
    """
    if data.payload_mass is None or not np.any(data.payload_mass > 0.0):
        return ()
    index = np.clip(np.searchsorted(data.time, at, side="right") - 1, 0, len(data.time) - 1)
    return tuple(float(m) for m in data.payload_mass[index])


class EnergyTexts(Protocol):
    """What :func:`design_texts` reads of a playback: its times and each design's battery figures."""

    @property
    def time(self) -> Array:
        """Sample times (K,) [s], increasing."""
        ...

    @property
    def battery_energy_J(self) -> dict[str, float] | None:
        """Each design's battery energy of ``result.json`` per ``battery_period`` [J]; None: none."""
        ...

    @property
    def battery_period(self) -> str:
        """``cycle`` or ``duty period``."""
        ...

    @property
    def battery_power(self) -> dict[str, Array] | None:
        """Each design's battery power over the cycle (K,) [W]; None: not in the result."""
        ...


def design_texts(
    name: str, layout: str, data: EnergyTexts, at: Array, power: Array | None, suffix: str = ""
) -> tuple[str, tuple[str, ...]]:
    """A design's caption and per-frame notes (:func:`energy_notes`) in a playback of layout ``layout``.

    The caption names the design (``suffix`` after it; ", ghost" for the initial design overlaid) and,
    where the notes accumulate the cycle's battery energy and the result has a duty model, the
    result's battery energy per duty period (cycle and rest), the figure its summary answers in.
    """
    caption = f"{name} design{suffix}" + (", ghost" if layout == "overlay" and name == "initial" else "")
    battery = None if data.battery_energy_J is None else data.battery_energy_J.get(name)
    trace = None if data.battery_power is None else data.battery_power.get(name)
    if trace is not None and battery is not None and data.battery_period != "cycle":
        caption += f": {battery / 1e3:.2f} kJ per {data.battery_period}"
    return caption, energy_notes(data.time, at, power, battery, data.battery_period, trace)


def energy_notes(
    time: Array,
    at: Array,
    power: Array | None,
    battery_J: float | None = None,
    period: str = "cycle",
    battery_power: Array | None = None,
) -> tuple[str, ...]:
    """Per-frame texts: time [s] and the energy, named with its boundary.

    With ``battery_power`` (the power the battery delivers at ``time`` [W], the trajectory's
    ``<design>_battery_power``) the battery energy of the cycle so far (trapezoid rule, the result's
    own quadrature) and its total [kJ], the closed loop's wording
    (:func:`hiab_sim.env.closed_loop_battery.battery_notes`); else with ``battery_J`` (the result's
    figure per ``period``) that figure; else, with
    ``power`` (W at ``time``), the drives' cumulative net electrical energy and its total [kJ], saying
    that no battery figure exists; else the time alone.
    """
    if battery_power is not None:
        so_far = _cumulative(time, battery_power)
        cycle = so_far[-1] / 1e3
        return tuple(
            f"t = {t:5.2f} s   battery energy {e / 1e3:.3f} of {cycle:.3f} kJ per cycle (at the battery)"
            for t, e in zip(at, np.interp(at, time, so_far), strict=True)
        )
    if battery_J is not None:
        text = f"battery energy {battery_J / 1e3:.3f} kJ per {period} (at the battery)"
        return tuple(f"t = {t:5.2f} s   {text}" for t in at)
    if power is None:
        return tuple(f"t = {t:5.2f} s   (no energy figure in this result)" for t in at)
    cumulative = _cumulative(time, power)
    total = cumulative[-1] / 1e3
    return tuple(
        f"t = {t:5.2f} s   drives' net electrical energy {e / 1e3:.3f} of {total:.3f} kJ (no battery figure)"
        for t, e in zip(at, np.interp(at, time, cumulative), strict=True)
    )


def _cumulative(time: Array, power: Array) -> Array:
    """int_t0^t_k power dt [J] at every sample (trapezoid rule), 0 at the first."""
    steps = 0.5 * (power[1:] + power[:-1]) * np.diff(time)
    return np.concatenate([[0.0], np.cumsum(steps)])


def load_power(result_dir: str | Path, data: PlaybackData) -> dict[str, Array]:
    """Net electrical power summed over the actuators [W] per design, from ``trajectory.npz``.

    Designs without a ``<design>_electrical_power`` array (K, actuators) are left out.
    """
    trajectory = read_trajectory(result_dir)
    out: dict[str, Array] = {}
    for motion in data.designs:
        key = f"{motion.name}_electrical_power"
        if key in trajectory.arrays:
            power = trajectory.design(motion.name, "electrical_power")
            if len(power) != len(data.time):
                raise ConfigError(f"{trajectory.path}: array '{key}' must have {len(data.time)} rows")
            out[motion.name] = power.sum(axis=1)
    return out


def crane_video(
    result_dir: str | Path,
    output: str | Path | None,
    fps: float,
    size: tuple[int, int],
    mode: Mode,
    layout: Layout,
    progress: Callable[[int, int], None] | None,
) -> Path:
    """The playback video of a crane file's result (:func:`hiab_sim.render.result_views.render_result`'s arguments)."""
    data = load_playback(result_dir)
    output = Path(result_dir) / VIDEO_NAME if output is None else Path(output)
    _check_size(size, even=output.suffix.lower() == ".mp4")
    check_output_path(output, (".mp4", ".gif"), "video")
    ffmpeg_path()
    with playback_renderer(data, fps, size, mode, layout, energy=load_power(result_dir, data)) as renderer:
        return write_video(renderer, output, size, fps, progress)


def crane_still(
    result_dir: str | Path, output: str | Path, at_time: float | None, size: tuple[int, int], layout: Layout
) -> Path:
    """One frame (.png) of a crane file's result at the 30 fps frame nearest ``at_time`` [s] (None: the last).

    Reached through :func:`hiab_sim.render.still.render_still`, which checks the OpenGL backend first.
    """
    data = load_playback(result_dir)
    _check_size(size, even=False)
    output = check_output_path(Path(output), (".png",), "image")
    t = still_time(at_time, float(data.time[0]), float(data.time[-1]))
    fps = 30.0
    with playback_renderer(data, fps, size, "kinematic", layout, energy=load_power(result_dir, data)) as renderer:
        last = len(renderer) - 1
        index = min(round((t - data.time[0]) * fps), last)
        return write_image(output, renderer.frame(index))


def _check_size(size: tuple[int, int], even: bool) -> None:
    width, height = size
    if width < 32 or height < 32 or width > 4096 or height > 4096 or (even and (width % 4 or height % 2)):
        allowed = "width and height in [32, 4096] px" + (", width a multiple of 4, height even" if even else "")
        raise InvalidInputError("size", f"{width}x{height}", allowed)

"""``trajectory.npz``: its declared arrays (key, shape, unit, meaning), schema version, writer and checked reader.

A result folder's ``trajectory.npz`` holds one task's motion on its fine grid (SI units) for both
designs of the result, under the keys of :data:`ARRAYS` (``{design}`` is ``initial`` or
``optimal``). A study of several tasks also holds every task k under ``task<k>_<key>``; the
unprefixed keys are its first task's. ``schema_version`` (a 0-d integer array) is
:data:`SCHEMA_VERSION`; files written before it was declared have none and the same keys
(version 0).

Shapes: ``K`` samples; ``J`` independent joints (the machine's joint order, e.g. rad, rad, m for
the XS 031's two booms and telescope); ``A`` actuators (the EMLA set's order).
"""

from __future__ import annotations

import io
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from hiab_sim.arrays import Array
from hiab_sim.atomic_io import write_atomic
from hiab_sim.errors import ConfigError

TRAJECTORY_FILE = "trajectory.npz"
#: Version of the array schema below; bump it when a key changes meaning or shape.
SCHEMA_VERSION = 1
VERSION_KEY = "schema_version"
#: The designs every result holds.
DESIGNS = ("initial", "optimal")


@dataclass(frozen=True)
class ArraySpec:
    """One declared array of ``trajectory.npz``.

    Attributes:
        key: Its key; ``{design}`` stands for each of :data:`DESIGNS`.
        shape: ``"K"`` or ``"K, J"`` / ``"K, A"`` / ``"K, 3"`` (module docstring).
        unit: SI unit of its values (per column where they differ).
        description: What it holds, and at which boundary for powers.

    """

    key: str
    shape: str
    unit: str
    description: str

    def keys(self) -> tuple[str, ...]:
        """The concrete keys (one per design where the key names one)."""
        if "{design}" in self.key:
            return tuple(self.key.format(design=d) for d in DESIGNS)
        return (self.key,)


ARRAYS: tuple[ArraySpec, ...] = (
    ArraySpec("time", "K", "s", "sample instants of the task's fine grid, increasing"),
    ArraySpec(
        "reference_tcp",
        "K, 3",
        "m",
        "the reference: TCP x, y in the source world frame {W} and the TCP's out-of-plane z there (constant)",
    ),
    ArraySpec("{design}_position", "K, J", "rad or m", "independent joint positions of the design's trajectory"),
    ArraySpec("{design}_velocity", "K, J", "rad/s or m/s", "their time derivatives"),
    ArraySpec("{design}_acceleration", "K, J", "rad/s^2 or m/s^2", "their second time derivatives"),
    ArraySpec("{design}_tcp", "K, 3", "m", "the TCP the trajectory reaches (same frame as reference_tcp)"),
    ArraySpec("{design}_actuator_force", "K, A", "N", "load-side actuator force along its line, > 0 pushing"),
    ArraySpec("{design}_actuator_velocity", "K, A", "m/s", "actuator rod velocity, > 0 extending"),
    ArraySpec("{design}_actuator_stroke", "K, A", "m", "actuator stroke x from its retracted length"),
    ArraySpec(
        "{design}_electrical_power",
        "K, A",
        "W",
        "electrical power of each EMLA drive at its input (per drive, > 0 drawn): at its DC-bus terminals where the "
        "EMLA file models the inverter in drive_losses (battery.inverter_efficiency 1), else at the motor terminals",
    ),
    ArraySpec(
        "{design}_battery_power",
        "K",
        "W",
        "power the battery delivers over the cycle (at the battery, > 0 discharging): every drive through its "
        "inverter and the shared DC bus, at the winding temperature of the study's duty; its trapezoid integral "
        "is energy.<design>.duty.cycle_battery_energy_J (without a duty: energy.<design>.battery_energy_J)",
    ),
    ArraySpec("payload_mass", "K", "kg", "payload carried at the TCP, m(t) of the task's schedule (0 while not held)"),
)


def declared_keys(prefix: str = "") -> tuple[str, ...]:
    """Every concrete key of :data:`ARRAYS` (with a task prefix such as ``task1_``)."""
    return tuple(prefix + key for spec in ARRAYS for key in spec.keys())


def trajectory_bytes(arrays: Mapping[str, Array]) -> bytes:
    """``trajectory.npz``'s bytes: ``arrays`` (which must hold every declared key) and the schema version."""
    missing = [key for key in declared_keys() if key not in arrays]
    if missing:
        raise ValueError(f"trajectory arrays lack declared keys {missing}")
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **{VERSION_KEY: np.array(SCHEMA_VERSION)}, **arrays)  # type: ignore[arg-type]
    return buffer.getvalue()


def write_trajectory(folder: Path, arrays: Mapping[str, Array]) -> Path:
    """Write ``folder/trajectory.npz`` atomically; return its path."""
    path = Path(folder) / TRAJECTORY_FILE
    write_atomic(path, trajectory_bytes(arrays))
    return path


@dataclass(frozen=True)
class Trajectory:
    """The checked arrays of one ``trajectory.npz`` (read with :func:`read_trajectory`).

    Attributes:
        path: The file.
        version: Its schema version (0: written before the schema was declared).
        arrays: Every array of the file, as read.

    """

    path: Path
    version: int
    arrays: Mapping[str, NDArray[np.generic]]

    def get(self, key: str, prefix: str = "") -> Array:
        """A declared array as float, checked: present, numeric, finite, K rows (one-line ConfigError)."""
        name = prefix + key
        if name not in self.arrays:
            raise ConfigError(f"{self.path}: missing array '{name}'")
        value = self.arrays[name]
        if not np.issubdtype(value.dtype, np.number) or value.ndim not in (1, 2):
            raise ConfigError(f"{self.path}: array '{name}' has shape {value.shape} of {value.dtype}, expected numbers")
        if not np.all(np.isfinite(value)):
            raise ConfigError(f"{self.path}: array '{name}' holds NaN or inf")
        time = self.arrays.get(prefix + "time")
        if key != "time" and time is not None and len(value) != len(time):
            raise ConfigError(f"{self.path}: array '{name}' has {len(value)} rows, 'time' has {len(time)}")
        return np.asarray(value, dtype=float)

    def time(self, prefix: str = "") -> Array:
        """The sample instants [s]: at least two, increasing."""
        t = self.get("time", prefix)
        if t.ndim != 1 or len(t) < 2 or not np.all(np.diff(t) > 0):
            raise ConfigError(f"{self.path}: 'time' must hold at least 2 increasing samples")
        return t

    def design(self, design: str, kind: str, prefix: str = "") -> Array:
        """``<design>_<kind>`` (e.g. ``optimal``, ``position``) as a 2-d float array."""
        value = self.get(f"{design}_{kind}", prefix)
        if value.ndim != 2:
            raise ConfigError(f"{self.path}: array '{prefix}{design}_{kind}' has shape {value.shape}, expected (K, n)")
        return value


def read_trajectory(folder: str | Path) -> Trajectory:
    """Read a result folder's ``trajectory.npz`` (or the file itself); a broken file is one ConfigError line.

    Files of a newer schema version than this code's are refused, naming both versions.
    """
    path = Path(folder)
    path = path / TRAJECTORY_FILE if path.is_dir() else path
    if not path.is_file():
        raise ConfigError(f"{path.parent} has no {TRAJECTORY_FILE} (write one with 'hiab-sim optimize')")
    try:
        with np.load(path, allow_pickle=False) as npz:
            arrays = {key: np.asarray(npz[key]) for key in npz.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as error:
        raise ConfigError(f"{path}: not a valid .npz archive: {error}") from None
    version = int(arrays.pop(VERSION_KEY)) if VERSION_KEY in arrays else 0
    if version > SCHEMA_VERSION:
        raise ConfigError(
            f"{path}: {VERSION_KEY} {version} is newer than this hiab-sim reads ({SCHEMA_VERSION}): upgrade hiab-sim"
        )
    return Trajectory(path, version, arrays)


def battery_powers(trajectory: Trajectory) -> dict[str, Array] | None:
    """Each design's ``<design>_battery_power`` (K,) [W] of ``trajectory``; None where a file predates the array."""
    if not all(f"{name}_battery_power" in trajectory.arrays for name in DESIGNS):
        return None
    out = {name: trajectory.get(f"{name}_battery_power") for name in DESIGNS}
    for name, value in out.items():
        if value.ndim != 1:
            raise ConfigError(f"{trajectory.path}: array '{name}_battery_power' has shape {value.shape}, expected (K,)")
    return out

"""The one reader of a result folder: ``result.json`` (typed) and ``trajectory.npz`` (checked).

Every command that reads a run (``mjcf --from-result``, ``compare``, ``render``, ``simulate``,
``energy-map --result``, the Python API) opens it with :func:`open_run` or :func:`read_result`: the
folder's checks and their one-line messages live here. ``result.json`` is read as a typed
:class:`~hiab_sim.results.schema.Result` (or a smaller view such as the renderer's
:class:`~hiab_sim.results.playback_view.PlaybackView`); ``trajectory.npz`` through the declared schema of
:mod:`hiab_sim.results.trajectory_file`. Tools that need a digest use :class:`RunSummary`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Generic, TypeVar

from hiab_sim.crane.description import Crane
from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.machine.description import Machine
from hiab_sim.machine.design import MachineDesign
from hiab_sim.machine.loader import PRESETS as MACHINE_PRESETS
from hiab_sim.machine.loader import load_machine
from hiab_sim.resources import Source
from hiab_sim.results.design_values import DesignValues
from hiab_sim.results.schema import RESULT_FILE, Result, read_json_as
from hiab_sim.results.trajectory_file import TRAJECTORY_FILE, Trajectory, read_trajectory

View = TypeVar("View")

#: Designs a result holds, in the order tools show them.
DESIGNS = ("initial", "optimal")
_HINT = "write one with 'hiab-sim optimize'"


@dataclass(frozen=True)
class DesignSummary:
    """One design of a run: its decision variables [m], energies [J], per-actuator peaks and envelope margins."""

    lengths: DesignValues
    net_energy_J: float
    drawn_energy_J: float
    battery_energy_J: float | None  # the energy the battery delivers (results with an energy section)
    peak_force_N: dict[str, float]
    peak_power_W: dict[str, float]
    min_envelope_margin: dict[str, float]
    max_violation: float


@dataclass(frozen=True)
class RunSummary:
    """What other tools need from a result folder."""

    folder: Path
    name: str
    variables: tuple[str, ...]  # ``chain.variable`` of each design value, the machine's names
    mounted: tuple[str, ...]  # the actuators whose mounting the decision variables move
    designs: dict[str, DesignSummary]
    saved_percent: float  # net energy saved by the optimum [%]
    recheck_max_violation: float  # fine-grid re-check of the optimum (scaled)
    objective: str  # the study's objective (energy.objective; costf2 for a result without an energy section)


@dataclass(frozen=True)
class RunFolder(Generic[View]):
    """A result folder as read by :func:`open_run`: its ``result.json`` and its ``trajectory.npz``."""

    folder: Path
    result: View
    trajectory: Trajectory


def _check_folder(folder: Path, files: tuple[str, ...]) -> None:
    if not folder.is_dir():
        raise ConfigError(f"result folder {folder} does not exist ({_HINT})")
    for name in files:
        if not (folder / name).is_file():
            raise ConfigError(f"{folder} is not a result folder: it has no {name} ({_HINT})")


def open_run(run_dir: str | Path, view: type[View]) -> RunFolder[View]:
    """Read a result folder: ``result.json`` as ``view`` (:class:`Result` or a smaller view) and ``trajectory.npz``.

    Raises:
        ConfigError: the folder or a file is missing or malformed (one line naming it).

    """
    folder = Path(run_dir)
    _check_folder(folder, (RESULT_FILE, TRAJECTORY_FILE))
    return RunFolder(folder, read_json_as(view, folder / RESULT_FILE), read_trajectory(folder))


def read_result(run_dir: str | Path) -> Result:
    """The typed result of a result folder (``result.json`` only; or that file itself).

    A missing folder or file, or a malformed one, is one :class:`ConfigError` line naming it.
    """
    path = Path(run_dir)
    if path.is_file():
        return read_json_as(Result, path)
    _check_folder(path, (RESULT_FILE,))
    return read_json_as(Result, path / RESULT_FILE)


def result_crane(run_dir: str | Path, crane: str) -> Crane:
    """The crane a result was computed for (its ``crane`` entry): a preset name, or a YAML file in the result folder."""
    path = Path(run_dir) / RESULT_FILE
    return load_crane(crane, relative_to=Source(str(path), path, False))


def result_machine(run_dir: str | Path, result: Result) -> Machine:
    """The machine file a machine file's result was computed for: a shipped name, or ``machine.yaml`` in the folder.

    Raises:
        InvalidInputError: the result is a crane file's (its designs are link lengths; :func:`result_crane`).

    """
    if not isinstance(result.optimal.lengths, MachineDesign):
        raise InvalidInputError("result", str(run_dir), "is a crane file's result (read it with result_crane)")
    source = result.crane
    path = Path(run_dir) / source
    return load_machine(path if source not in MACHINE_PRESETS and path.is_file() else source)


def design_lengths(result: Result, design: str) -> DesignValues:
    """The link lengths of ``design`` (``initial`` or ``optimal``) of a result [m]."""
    if design not in DESIGNS:
        raise InvalidInputError("--design", design, f"must be one of {list(DESIGNS)}")
    return (result.optimal if design == "optimal" else result.initial).lengths


def summarise(run_dir: str | Path) -> RunSummary:
    """Read a result folder into a :class:`RunSummary`; every name is the result's machine's."""
    folder = Path(run_dir)
    result = read_result(folder)
    designs = {}
    for name in DESIGNS:
        entry = result.optimal if name == "optimal" else result.initial
        energy = None if result.energy is None else getattr(result.energy, name)
        designs[name] = DesignSummary(
            lengths=entry.lengths,
            net_energy_J=entry.net_electrical_energy_J,
            drawn_energy_J=entry.drawn_energy_summed_drives_J,
            battery_energy_J=None if energy is None else energy.battery_energy_J,
            peak_force_N={a: p.peak_force_N for a, p in entry.actuators.items()},
            peak_power_W={a: p.peak_electrical_power_W for a, p in entry.actuators.items()},
            min_envelope_margin={a: p.min_envelope_margin for a, p in entry.actuators.items()},
            max_violation=entry.max_violation,
        )
    return RunSummary(
        folder=folder,
        name=result.name,
        variables=tuple(result.optimal.lengths.names),
        mounted=mounted_actuators(folder, result),
        designs=designs,
        saved_percent=result.improvement.net_energy_saved_percent,
        recheck_max_violation=result.recheck.max_violation_scaled,
        objective="costf2" if result.energy is None else result.energy.objective,
    )


def mounted_actuators(run_dir: str | Path, result: Result) -> tuple[str, ...]:
    """The actuators of the chains with decision variables (their EMLA names, as the result's actuators)."""
    if isinstance(result.optimal.lengths, MachineDesign):
        chains = result_machine(run_dir, result).chains
        return tuple(c.actuator.emla or c.name for c in chains if c.variables)
    return tuple(c.name for c in result_crane(run_dir, result.crane).chains)

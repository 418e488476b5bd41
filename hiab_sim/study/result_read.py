"""Reading a result folder's designs for other tools (``mjcf --from-result``, ``compare``).

:func:`read_result` is the one place that parses ``result.json`` for these tools; everything else
here works on :class:`RunSummary`, so switching to a typed result changes one function.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hiab_sim.crane.description import ChainLengths, Crane, LinkLengths
from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import ConfigError, InvalidInputError

RESULT_FILE = "result.json"
#: Designs a result holds, in the order tools show them.
DESIGNS = ("initial", "optimal")
#: Actuators whose peaks a result reports.
ACTUATORS = ("lift", "tilt", "telescope")
_HINT = "write one with 'hiab-sim optimize'"


@dataclass(frozen=True)
class DesignSummary:
    """One design of a run: lengths [m], energies [J], per-actuator peaks and envelope margins."""

    lengths: LinkLengths
    net_energy_J: float
    drawn_energy_J: float
    peak_force_N: dict[str, float]
    peak_power_W: dict[str, float]
    min_envelope_margin: dict[str, float]
    max_violation: float


@dataclass(frozen=True)
class RunSummary:
    """What other tools need from a result folder."""

    folder: Path
    name: str
    crane: Crane
    designs: dict[str, DesignSummary]
    saved_percent: float  # net energy saved by the optimum [%]
    recheck_max_violation: float  # fine-grid re-check of the optimum (scaled)


def read_result(run_dir: str | Path) -> dict[str, Any]:
    """Parse ``RUN_DIR/result.json``; a missing folder or file or invalid JSON is a one-line :class:`ConfigError`."""
    folder = Path(run_dir)
    if not folder.is_dir():
        raise ConfigError(f"result folder {folder} does not exist ({_HINT})")
    path = folder / RESULT_FILE
    if not path.is_file():
        raise ConfigError(f"{folder} is not a result folder: it has no {RESULT_FILE} ({_HINT})")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ConfigError(f"{path}: not valid JSON: {error}") from None
    if not isinstance(data, dict) or "crane" not in data or "optimal" not in data:
        raise ConfigError(f"{path}: not a hiab-sim result (no 'crane' and 'optimal' entries)")
    return data


def result_crane(run_dir: str | Path, result: dict[str, Any]) -> Crane:
    """The crane a result was computed for: a preset name, or a YAML file kept in the result folder."""
    source = str(result["crane"])
    local = Path(run_dir) / source
    if source.endswith((".yaml", ".yml")) and not Path(source).is_absolute() and local.is_file():
        return load_crane(local)
    return load_crane(source)


def design_lengths(result: dict[str, Any], design: str, where: str | Path = RESULT_FILE) -> LinkLengths:
    """The link lengths of ``design`` (``initial`` or ``optimal``) of a parsed result [m]."""
    if design not in DESIGNS:
        raise InvalidInputError("--design", design, f"must be one of {list(DESIGNS)}")
    try:
        chains = result[design]["lengths"]
        return LinkLengths(
            *(ChainLengths(*(float(chains[c][k]) for k in ("L", "Lc0", "Lc"))) for c in ("lift", "tilt"))
        )
    except (KeyError, TypeError, ValueError):
        raise ConfigError(f"{where}: '{design}.lengths' must map lift and tilt to numbers L, Lc0, Lc [m]") from None


def summarise(run_dir: str | Path) -> RunSummary:
    """Read a result folder into a :class:`RunSummary`."""
    folder = Path(run_dir)
    result = read_result(folder)
    where = folder / RESULT_FILE
    try:
        designs = {}
        for name in DESIGNS:
            entry = result[name]
            actuators = entry["actuators"]
            designs[name] = DesignSummary(
                lengths=design_lengths(result, name, where),
                net_energy_J=float(entry["net_electrical_energy_J"]),
                drawn_energy_J=float(entry["drawn_energy_without_regeneration_J"]),
                peak_force_N={a: float(actuators[a]["peak_force_N"]) for a in ACTUATORS},
                peak_power_W={a: float(actuators[a]["peak_electrical_power_W"]) for a in ACTUATORS},
                min_envelope_margin={a: float(actuators[a]["min_envelope_margin"]) for a in ACTUATORS},
                max_violation=float(entry["max_violation"]),
            )
        return RunSummary(
            folder=folder,
            name=str(result.get("name", folder.name)),
            crane=result_crane(folder, result),
            designs=designs,
            saved_percent=float(result["improvement"]["net_energy_saved_percent"]),
            recheck_max_violation=float(result["recheck"]["max_violation_scaled"]),
        )
    except (KeyError, TypeError, ValueError) as error:
        raise ConfigError(f"{where}: not a complete hiab-sim result (missing or bad entry {error})") from None

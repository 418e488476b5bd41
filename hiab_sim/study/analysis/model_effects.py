"""How much each part of the real EMLA model moves a study's optimum: the study re-optimised per model level.

The seed paper's EMLA model (eqs. ``Park_Transformation`` .. ``system_efficiency``) is lossless: ideal
transmission and inverter, R_s at its data-sheet value and a free rest between cycles. hiab-sim's
default EMLA set adds, in this order, the levels of :data:`LEVELS`:

1. ``paper``: the paper's model (``emla: paper``, the rest at zero torque and zero power);
2. ``drive_losses``: the default EMLA file's drive losses (transmission efficiencies, the inverter's
   c0 + c1 I + c2 I^2, the brake coil while released: :mod:`hiab_sim.emla.losses`) with R_s held at
   its reference value (the file's ``winding_resistance`` section left out) and the free rest;
3. ``hot_windings``: + R_s at the winding's periodic steady-state temperature
   (:mod:`hiab_sim.emla.electrothermal`), still the free rest;
4. ``hold_brake``: + the rest held by the holding brakes (``duty.hold: brake``, :mod:`hiab_sim.emla.hold`);
5. ``hold_motor``: level 4 with the motors holding the rest instead (``duty.hold: motor``).

Each level is the base study (its grid, reference, bounds, duty rate and objective) with only the
EMLA set and ``duty.hold`` changed, optimised from the study's own start like ``hiab-sim optimize``
(one start, no figures). A level whose start cannot be made feasible is a row ``infeasible`` with
the feasibility phase's message; any other failure stops the table.

    python -m hiab_sim.study.analysis.model_effects optimize/xs031_spiral.yaml --out DIR

writes ``DIR/<level>/`` (the level's result folder), ``DIR/studies/<level>.yaml`` (its study, and
``<level>_emla.yaml`` where the EMLA set is a modified copy) and ``DIR/model_effects.json`` (one row
per level: battery energy per duty period [J] at the start and the optimum, the saving [%], each
motor's peak winding temperature [deg C], the optimal lengths [m], SLSQP iterations).
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from hiab_sim.atomic_io import write_atomic
from hiab_sim.errors import ConfigError, InfeasibleStudyError
from hiab_sim.resources import Source, locate
from hiab_sim.study.spec.study import Study
from hiab_sim.study.spec.study_file import study_from_dict
from hiab_sim.yaml_fields import read_yaml

#: The file of the table in the output folder.
TABLE_FILE = "model_effects.json"
#: EMLA sets a level uses: the paper's preset, the base study's set, that set with R_s constant.
EMLA_CHOICES = ("paper", "base", "base_cold")


@dataclass(frozen=True)
class ModelLevel:
    """One row of the table: which EMLA set and which hold of the rest the study runs with."""

    key: str  # row and folder name
    label: str  # what the row adds, for the page
    emla: str  # one of EMLA_CHOICES
    hold: str  # duty.hold: none | brake | motor
    compared_with: str | None  # the key of the row whose energy this row's change is against (None: the first)

    def __post_init__(self) -> None:
        """Reject an unknown EMLA choice or hold."""
        if self.emla not in EMLA_CHOICES:
            raise ConfigError(f"model level {self.key}: emla must be one of {EMLA_CHOICES}, got {self.emla!r}")
        if self.hold not in ("none", "brake", "motor"):
            raise ConfigError(f"model level {self.key}: hold must be none, brake or motor, got {self.hold!r}")


#: The levels in table order (module docstring); each adds one effect to the row above, the last replaces one.
LEVELS: tuple[ModelLevel, ...] = (
    ModelLevel("paper", "paper model (`emla: paper`, free rest)", "paper", "none", None),
    ModelLevel(
        "drive_losses",
        "+ drive losses (transmission, inverter, brake coil; R_s at 20 °C, free rest)",
        "base_cold",
        "none",
        "paper",
    ),
    ModelLevel(
        "hot_windings", "+ hot windings (R_s at the periodic winding temperature)", "base", "none", "drive_losses"
    ),
    ModelLevel("hold_brake", "+ holding (`hold: brake`): the default study", "base", "brake", "hot_windings"),
    ModelLevel("hold_motor", "`hold: motor` instead of the brake", "base", "motor", "hot_windings"),
)


def _user(path: Path) -> Source:
    return Source(str(path), path, shipped=False)


def level_documents(base_file: Path, level: ModelLevel) -> tuple[dict[str, Any], dict[str, Any] | None]:
    """The level's study mapping and, for ``base_cold``, its EMLA mapping (else None).

    Paths in the mapping are absolute; ``name`` is ``<base name>_<level key>``. ``base_cold`` is the
    base study's EMLA document without its ``winding_resistance`` section (R_s constant at
    ``pmsm.stator_resistance``).
    """
    study = read_yaml(_user(base_file))
    if not isinstance(study, dict):
        raise ConfigError(f"{base_file}: a study file is a mapping")
    study = copy.deepcopy(study)
    for key in ("crane", "emla"):
        value = study.get(key)
        if value is not None:
            found = locate(str(value), "crane" if key == "crane" else "emla", relative_to=_user(base_file))
            study[key] = str(value) if found.shipped and found.label == str(value) else str(found.file)
    study["name"] = f"{study.get('name', base_file.stem)}_{level.key}"
    duty = dict(study.get("duty") or {})
    if not duty:
        raise ConfigError(f"{base_file}: the model levels need a duty (cycles_per_hour or rest_time)")
    duty["hold"] = level.hold
    study["duty"] = duty
    emla: dict[str, Any] | None = None
    if level.emla == "paper":
        study["emla"] = "paper"
    elif level.emla == "base_cold":
        document = read_yaml(locate(str(study.get("emla") or "default"), "emla"))
        if not isinstance(document, dict) or "winding_resistance" not in document:
            raise ConfigError(f"{base_file}: its EMLA set has no winding_resistance section to leave out")
        emla = {k: v for k, v in document.items() if k != "winding_resistance"}
    return study, emla


def level_study(base_file: Path, level: ModelLevel, folder: Path) -> Study:
    """Write the level's study (and EMLA) file into ``folder`` and build the study from it."""
    study, emla = level_documents(base_file, level)
    folder.mkdir(parents=True, exist_ok=True)
    if emla is not None:
        emla_file = folder / f"{level.key}_emla.yaml"
        write_atomic(emla_file, yaml.safe_dump(emla, sort_keys=False))
        study["emla"] = str(emla_file.resolve())
    study_file = folder / f"{level.key}.yaml"
    write_atomic(study_file, yaml.safe_dump(study, sort_keys=False))
    return study_from_dict(study, study_file)


def _level_fields(level: ModelLevel) -> dict[str, Any]:
    return {
        "key": level.key,
        "label": level.label,
        "emla": level.emla,
        "hold": level.hold,
        "compared_with": level.compared_with,
    }


def row(level: ModelLevel, result: dict[str, Any]) -> dict[str, Any]:
    """One table row from a level's ``result.json`` (the parsed JSON): energies [J], temperatures [deg C]."""
    energy = result["energy"]
    return {
        **_level_fields(level),
        "status": "optimised",
        "message": result["solver"]["message"],
        "iterations": result["solver"]["iterations"],
        "duty": energy["duty"],
        "initial_battery_energy_J": energy["initial"]["battery_energy_J"],
        "battery_energy_J": energy["optimal"]["battery_energy_J"],
        "battery_energy_saved_percent": energy["battery_energy_saved_percent"],
        "peak_winding_temperature_C": {
            name: t["peak_winding_temperature_C"] for name, t in energy["optimal"]["thermal"].items()
        },
        "lengths": result["optimal"]["lengths"],
    }


def run_model_effects(
    base_file: str | Path, out: str | Path, levels: tuple[ModelLevel, ...] = LEVELS
) -> dict[str, Any]:
    """Optimise the base study at every level and write the table (module docstring); return it."""
    from hiab_sim.study.run import run_study

    base, out = Path(str(locate(str(base_file), "study").file)), Path(out)
    rows = []
    for level in levels:
        study = level_study(base, level, out / "studies")
        try:
            output = run_study(study, out / level.key, progress=None, figures=False, force=True)
        except InfeasibleStudyError as error:  # the level's answer: no design of the bounds holds its limits
            rows.append({**_level_fields(level), "status": "infeasible", "message": str(error)})
            continue
        rows.append(row(level, output.result.to_json()))
    table = {"study": base.stem, "study_file": str(base), "rows": rows}
    write_atomic(out / TABLE_FILE, json.dumps(table, indent=1) + "\n")
    return table


def main(argv: list[str] | None = None) -> int:
    """``STUDY --out DIR``: optimise STUDY at every model level and write DIR/model_effects.json."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", help="a shipped study name or a study file with a duty")
    parser.add_argument("--out", type=Path, required=True, help="output folder")
    args = parser.parse_args(argv)
    table = run_model_effects(args.study, args.out)
    for r in table["rows"]:
        energy = f"{r['battery_energy_J']:.1f} J" if r["status"] == "optimised" else r["message"].splitlines()[0]
        print(f"{r['key']}: {energy}")
    print(f"wrote {args.out / TABLE_FILE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

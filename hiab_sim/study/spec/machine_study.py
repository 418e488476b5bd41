"""A study of a machine file (``machine:``): the keys of a crane file's study, the machine's names and variables."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from hiab_sim.emla.config import load_emla_set
from hiab_sim.errors import ConfigError
from hiab_sim.machine.loader import PRESETS as MACHINE_PRESETS
from hiab_sim.machine.loader import load_machine
from hiab_sim.machine.mounting import MachineMountingSpace
from hiab_sim.resources import Source, locate
from hiab_sim.structure.machine_structure import machine_pin_names
from hiab_sim.structure.settings import StructureSettings
from hiab_sim.study.machines.machine_model import MachineModel
from hiab_sim.study.spec.settings import (
    bounds_from_mapping,
    shared_sections,
    work_sections,
)
from hiab_sim.study.spec.study import Study
from hiab_sim.study.spec.tasks import column_names
from hiab_sim.yaml_fields import mapping, number


def machine_study_from_dict(top: dict[str, Any], file: Source) -> Study:
    """A study of a machine file (``machine:``): its decision variables, their bounds and its names are the file's.

    Keys as a crane study's, except: ``machine`` (a shipped machine or a path next to the study),
    ``tracked`` (the tracked coordinates beyond the TCP's x, y: joint names or ``tcp_angle``;
    default ``tcp_angle`` for each), ``initial_lengths`` (a mapping ``chain.variable: value``, default
    the file's values) and ``bounds`` without per-chain bounds (the file declares them). ``mounting``
    gives polygons per chain and pivot (:mod:`hiab_sim.machine.mounting`); ``build`` holds the robust
    rows; ``structure`` names the machine's hinges (joint names) and loop pins in ``pin_load_limits``.
    """
    if "crane" in top:
        raise ConfigError("study: 'crane' and 'machine' name the same thing: give one of them")
    source = str(top["machine"])
    path = Path(source)
    folder = Path(str(file.file)).parent
    if source not in MACHINE_PRESETS and not path.is_absolute() and (folder / path).is_file():
        path = folder / path
    machine_file = locate(source if source in MACHINE_PRESETS else path, "machine")
    machine = load_machine(machine_file)
    n = len(machine.joint_names)
    tracked_value = top.get("tracked", ["tcp_angle"] * (n - 2))
    if not isinstance(tracked_value, list) or not all(isinstance(t, str) for t in tracked_value):
        raise ConfigError(f"study: tracked: expected a list of names, got {tracked_value!r}")
    tracked = tuple(tracked_value)
    model = MachineModel(machine, tracked)
    emla_source = str(top.get("emla", ""))
    if not emla_source:
        raise ConfigError("study: a machine file's study names its EMLA file (emla:)")
    emlas = load_emla_set(locate(emla_source, "emla", relative_to=file)).renamed(model.actuator_names)
    low, up = model.design_bounds()
    bounds = bounds_from_mapping(top["bounds"], chains=False, joints=n)
    bounds = replace(
        bounds,
        xi_low=tuple(map(float, low)),
        xi_up=tuple(map(float, up)),
        xi_fields=tuple(
            f"{machine_file.label}: chains.{k.replace('.', '.variables.')}.bounds" for k in model.design_names
        ),
    )
    work = work_sections(top, file, column_names(model))
    tasks = work["tasks"]
    # the spiral and pick-and-place kinds prescribe the third tracked coordinate as a crane's telescope:
    # a machine of three joints whose third tracked coordinate is a joint may use them
    prescribed = len(model.tracked_names) == 3 and model.tracked_names[2] in model.joint_names
    for i, task in enumerate(tasks):
        if task.reference.kind != "csv" and not prescribed:
            raise ConfigError(
                f"study: tasks[{i}] ({task.name}): this machine's study takes 'kind: csv' references (got "
                f"'{task.reference.kind}', which prescribes the third tracked coordinate as a joint; tracked: "
                f"{', '.join(model.tracked_names)})"
            )
    initial = model.default_design
    if "initial_lengths" in top:
        given = mapping(top["initial_lengths"], "initial_lengths", set(model.design_names), set())
        values = initial.as_array()
        for key, value in given.items():
            values[model.design_names.index(key)] = number(value, f"initial_lengths.{key}")
        initial = model.design(values)
    return Study(
        **work,
        crane_source=source,
        crane_description=None,
        emla_source=emla_source,
        emlas=emlas,
        initial_lengths=initial,
        bounds=bounds,
        **shared_sections(top, tuple(model.actuator_names)),  # the EMLA names, the keys of emlas and results
        crane_file=machine_file,
        machine=machine,
        tracked=tracked,
        structure=StructureSettings.from_mapping(top.get("structure"), machine_pin_names(machine)),
        mounting=None if top.get("mounting") is None else MachineMountingSpace.from_mapping(top["mounting"], machine),
    )

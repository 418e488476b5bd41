"""The plant's drive-train stiffness is the EMLA file's: the same number, and it follows the file when it changes."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from closed_loop_helper import synthetic_plan

from hiab_sim.crane.description import Crane
from hiab_sim.emla.config import load_emla_set
from hiab_sim.env import make_environment
from hiab_sim.env.plant import load_plant
from hiab_sim.env.plant.drivetrain import drive_train_stiffness
from hiab_sim.errors import InvalidInputError
from hiab_sim.resources import shipped

NAMES = ("lift", "tilt", "telescope")


def _hand_stiffness(document: dict, name: str, stroke: float) -> float:
    """1/k = (l_0 + x) / (E pi d_r^2 / 4) + 1/k_nut + 1/k_bearing + n / k_pin from the YAML's own numbers."""

    def value(section: str, key: str) -> float:
        own = document["actuators"][name].get(section, {})
        return float((own[key] if key in own else document[section][key])["value"])

    area = math.pi * value("screw", "root_diameter") ** 2 / 4.0
    screw = (value("drive_stiffness", "support_length") + stroke) / (value("screw", "elastic_modulus") * area)
    rest = 1.0 / value("drive_stiffness", "nut_stiffness") + 1.0 / value("drive_stiffness", "bearing_stiffness")
    pins = value("drive_stiffness", "pin_count") / value("drive_stiffness", "pin_stiffness")
    return 1.0 / (screw + rest + pins)


def _strokes() -> np.ndarray:
    """Strokes of a motion (N, 3) [m] whose means are 0.30, 0.25 and 0.40 m."""
    ramp = np.linspace(-0.1, 0.1, 11)[:, None]
    return np.array([0.30, 0.25, 0.40]) + ramp


def test_plant_stiffness_is_the_emla_files_series_sum() -> None:
    """Per drive, k_s equals the series sum written out from emla_xs031.yaml's numbers at the mean stroke."""
    document = yaml.safe_load(shipped("emla", "xs031").read_text())
    k = drive_train_stiffness(load_emla_set("xs031"), _strokes())
    hand = [_hand_stiffness(document, name, x) for name, x in zip(NAMES, (0.30, 0.25, 0.40), strict=True)]
    np.testing.assert_allclose(k, hand, rtol=1e-12)
    assert 1.5e8 < k.min() and k.max() < 3.4e8  # the order of the plant's former 1.87e8 N/m


def test_plant_stiffness_follows_the_emla_file(tmp_path: Path, crane: Crane) -> None:
    """Halving the nut's stiffness in a copy of the EMLA file changes the assembled plant's spring to the new sum.

    The spring is measured on the built environment: a deflection d of the motor side against the
    rod gives the force k_s (d - b) beyond the free play b.
    """
    document = yaml.safe_load(shipped("emla", "paper").read_text())
    document["drive_stiffness"]["nut_stiffness"]["value"] = 5.0e8
    path = tmp_path / "soft_nut.yaml"
    path.write_text(yaml.safe_dump(document))
    plant = load_plant("realistic").only("drive_train")
    springs = {}
    for label, emlas in (("shipped", load_emla_set("paper")), ("soft", load_emla_set(path))):
        plan = dataclasses.replace(synthetic_plan(crane), emlas=emlas)
        env = make_environment(plan, plant=plant)
        train = env.physics.drive_train
        assert train is not None
        mean = np.mean(env.task.motion.stroke, axis=0)
        source = document if label == "soft" else yaml.safe_load(shipped("emla", "paper").read_text())
        hand = np.array([_hand_stiffness(source, name, x) for name, x in zip(NAMES, mean, strict=True)])
        rod = np.zeros(3)
        d = 1.0e-3
        train.position = np.full(3, d)
        train.velocity = np.zeros(3)
        force = train.spring_force(rod, np.zeros(3))
        np.testing.assert_allclose(force, hand * (d - 0.5 * plant.drive_train.backlash_m), rtol=1e-12)
        springs[label] = force
        env.physics.free()
    assert np.all(springs["soft"] < 0.9 * springs["shipped"])


def test_a_drive_train_without_emla_stiffness_data_is_named() -> None:
    """An EMLA set without drive_stiffness data cannot give the plant its spring: the error names the drives."""
    emlas = load_emla_set("xs031")
    bare = emlas.replaced(lift=dataclasses.replace(emlas.lift, stiffness=None))
    with pytest.raises(InvalidInputError, match="lift") as error:
        drive_train_stiffness(bare, _strokes())
    assert error.value.field == "drive_train"

"""EMLA parameter files: the XS 031 preset, provenance, and the named-field errors for bad input."""

from __future__ import annotations

import copy
import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from hiab_sim.cli import main
from hiab_sim.emla import (
    ACTUATOR_NAMES,
    EmlaParams,
    emla_set_from_mapping,
    envelope_margins,
    load_emla_set,
    peak_force,
    top_speed,
)
from hiab_sim.emla.config import PROVENANCE_KINDS
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import shipped

# Hydraulic cylinders of the XS 031 (shared/reference/hiab-xs031.yaml, hydraulic_cylinders):
# bore, rod [m] and the 19.0 MPa supply pressure.
HYDRAULIC = {"lift": (0.080, 0.045), "tilt": (0.080, 0.045), "telescope": (0.050, 0.030)}
SUPPLY_PRESSURE = 19.0e6


def _preset_document() -> dict[str, Any]:
    return yaml.safe_load(shipped("emla", "paper").read_text())


def test_preset_iterates_lift_tilt_telescope_in_order() -> None:
    """The default set holds the three XS 031 actuators and iterates them in crane order."""
    emlas = load_emla_set("paper")
    assert tuple(p.name for p in emlas) == ACTUATOR_NAMES
    assert emlas["tilt"] is emlas.tilt


def test_every_preset_value_carries_a_provenance_label() -> None:
    """Each parameter of the preset says whether it was read, estimated, derived or a model choice."""
    for params in load_emla_set("paper"):
        assert len(params.provenance) >= 15
        for key, source in params.provenance:
            assert source.split(":", 1)[0] in PROVENANCE_KINDS, (key, source)
        assert params.source_of("pmsm.flux_linkage").startswith("read")
        assert params.source_of("pmsm.peak_torque").startswith("estimate")


def test_hydraulic_comparison_forces_match_bore_times_supply_pressure() -> None:
    """The preset's hydraulic push/pull forces are pi/4 bore^2 p and pi/4 (bore^2 - rod^2) p (0.1 %)."""
    for params in load_emla_set("paper"):
        bore, rod = HYDRAULIC[params.name]
        push = math.pi / 4 * bore**2 * SUPPLY_PRESSURE
        pull = math.pi / 4 * (bore**2 - rod**2) * SUPPLY_PRESSURE
        assert params.hydraulic_push_force == pytest.approx(push, rel=1e-3)
        assert params.hydraulic_pull_force == pytest.approx(pull, rel=2e-3)


@pytest.mark.parametrize("name", ACTUATOR_NAMES)
def test_each_emla_pushes_at_least_as_hard_as_the_hydraulic_cylinder(name: str) -> None:
    """Peak EMLA force >= the 190 bar cylinder it replaces (95.5 kN lift/tilt, 37.3 kN telescope).

    The envelope also admits that force while the rod starts to move outwards.
    """
    params = load_emla_set("paper")[name]
    hydraulic = {"lift": 95.5e3, "tilt": 95.5e3, "telescope": 37.3e3}[name]
    assert params.hydraulic_push_force == hydraulic
    assert peak_force(params) >= hydraulic
    creep = 5.0 * params.motor.friction_smoothing_speed / params.transmission_ratio
    assert np.all(envelope_margins(params, hydraulic, creep, 0.0) >= 0.0)
    assert np.all(envelope_margins(params, -params.hydraulic_pull_force, -creep, 0.0) >= 0.0)


def test_preset_top_speeds_follow_from_rated_motor_speed() -> None:
    """Top rod speed = rated speed x rho / (2 pi G): 0.1875 m/s lift/tilt, 0.375 m/s telescope."""
    emlas = load_emla_set("paper")
    assert top_speed(emlas.lift) == pytest.approx(0.1875, rel=1e-12)
    assert top_speed(emlas.telescope) == pytest.approx(0.375, rel=1e-12)


@pytest.mark.parametrize(
    ("section", "key", "value", "field"),
    [
        ("lift", "gear_ratio", 0.0, "lift.gear_ratio"),
        ("tilt", "gear_ratio", -4.0, "tilt.gear_ratio"),
        ("telescope", "screw_lead", 0.0, "telescope.screw_lead"),
        ("lift", "screw_lead", -0.01, "lift.screw_lead"),
        ("lift", "viscous_friction", -1.0, "lift.viscous_friction"),
        ("pmsm", "pole_pairs", 0, "pmsm.pole_pairs"),
        ("pmsm", "pole_pairs", -4, "pmsm.pole_pairs"),
        ("pmsm", "pole_pairs", 2.5, "pmsm.pole_pairs"),
        ("pmsm", "stator_resistance", -0.1, "pmsm.stator_resistance"),
        ("pmsm", "flux_linkage", 0.0, "pmsm.flux_linkage"),
        ("pmsm", "Lq", -1e-3, "pmsm.Lq"),
        ("pmsm", "friction_smoothing_speed", 0.0, "pmsm.friction_smoothing_speed"),
        ("pmsm", "rotor_coulomb_friction", 50.0, "pmsm.rotor_coulomb_friction"),
    ],
)
def test_out_of_range_value_raises_error_naming_field_value_and_range(
    section: str, key: str, value: float, field: str
) -> None:
    """A bad value in the YAML raises InvalidInputError whose message names field, value and range."""
    document = _preset_document()
    node = document["pmsm"] if section == "pmsm" else document["actuators"][section]
    node[key] = value
    with pytest.raises(InvalidInputError) as info:
        emla_set_from_mapping(document)
    assert info.value.field == field
    message = str(info.value)
    assert field in message and f"{value:g}" in message and "must be" in message


def test_dataclass_rejects_bad_values_when_built() -> None:
    """EmlaParams validates at construction, not only in the loader."""
    lift = load_emla_set("paper").lift
    with pytest.raises(InvalidInputError, match=r"lift\.gear_ratio = -1 is out of range: must be"):
        dataclasses.replace(lift, gear_ratio=-1.0)
    with pytest.raises(InvalidInputError, match=r"pmsm\.stator_resistance"):
        dataclasses.replace(lift.motor, stator_resistance=-0.5)
    assert isinstance(dataclasses.replace(lift, gear_ratio=5.0), EmlaParams)


@pytest.mark.parametrize(
    ("edit", "pattern"),
    [
        (lambda d: d["pmsm"].update(bogus=1.0), "unknown key.*bogus"),
        (lambda d: d["actuators"]["lift"].pop("screw_lead"), "missing key.*screw_lead"),
        (lambda d: d["actuators"].clear(), "at least one actuator"),
        (lambda d: d["pmsm"].update(Ld="2.2e-3"), "expected a number.*1.0e\\+3"),
        (lambda d: d["pmsm"].update(Ld={"value": 2e-3, "source": "guess"}), "source must be"),
        (lambda d: d.update(extra={}), "unknown key.*extra"),
    ],
)
def test_malformed_document_raises_config_error(edit: Any, pattern: str) -> None:
    """Unknown, missing or non-numeric keys and bad provenance labels raise ConfigError."""
    document = _preset_document()
    edit(document)
    with pytest.raises(ConfigError, match=pattern):
        emla_set_from_mapping(document)


def test_set_missing_a_machine_actuator_is_refused_naming_the_actuators() -> None:
    """An EMLA file is read with any actuator names; a machine's check names what it lacks."""
    document = _preset_document()
    document["actuators"].pop("telescope")
    emlas = emla_set_from_mapping(document)
    assert emlas.names == ("lift", "tilt")
    with pytest.raises(
        InvalidInputError, match=r"actuators = 'lift, tilt' .*must be the machine's actuators: lift, tilt, telescope"
    ):
        emlas.renamed(("lift", "tilt", "telescope"))
    full = emla_set_from_mapping(_preset_document())
    assert full.renamed(("telescope", "lift", "tilt")).names == ("telescope", "lift", "tilt")


def test_unparsable_yaml_file_raises_config_error(tmp_path: Path) -> None:
    """A file that is not YAML, or not found, raises ConfigError."""
    bad = tmp_path / "bad.yaml"
    bad.write_text("pmsm: [unclosed\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_emla_set(bad)
    with pytest.raises(ConfigError, match="cannot read"):
        load_emla_set(tmp_path / "missing.yaml")


def test_actuator_may_override_motor_parameters_and_bare_numbers_are_accepted() -> None:
    """A per-actuator pmsm mapping overrides the shared motor; bare numbers load as 'unspecified'."""
    document = _preset_document()
    document["actuators"]["telescope"]["pmsm"] = {"peak_torque": 30.0}
    emlas = emla_set_from_mapping(copy.deepcopy(document))
    assert emlas.telescope.motor.peak_torque == 30.0
    assert emlas.lift.motor.peak_torque == 42.0
    assert emlas.telescope.source_of("pmsm.peak_torque") == "unspecified"


def test_cli_reports_bad_config_with_exit_status_2_and_no_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``hiab-sim emla-map --config`` with a negative resistance exits 2 with a one-line message."""
    document = _preset_document()
    document["pmsm"]["stator_resistance"]["value"] = -0.2
    path = tmp_path / "emla.yaml"
    path.write_text(yaml.safe_dump(document), encoding="utf-8")
    status = main(["emla-map", "--config", str(path), "-o", str(tmp_path / "x.png")])
    err = capsys.readouterr().err
    assert status == 2
    assert "pmsm.stator_resistance = -0.2 ohm is out of range" in err
    assert "Traceback" not in err
    assert not (tmp_path / "x.png").exists()

"""The plant file: the shipped preset's data and provenance, the variants, and bad input named by field."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from hiab_sim.env.plant import EFFECTS, load_plant
from hiab_sim.env.plant.config import CurrentLoop, DriveTrain, Mismatch, Sensors
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.resources import shipped

PROVENANCE = ("read", "estimate", "derived", "model")


def test_realistic_preset_states_a_source_for_every_number() -> None:
    """Every number of the shipped plant carries a source whose first word is read, estimate, derived or model."""
    plant = load_plant("realistic")
    assert plant.enabled == EFFECTS
    assert len(plant.provenance) >= 25  # the drive-train stiffness and the inverter losses are the EMLA file's
    for key, source in plant.provenance:
        assert source.split(":", 1)[0] in PROVENANCE, key


def test_variants_switch_effects_and_keep_the_data() -> None:
    """The ideal plant turns every effect off, only(x) keeps x alone; the numbers stay the file's."""
    plant = load_plant("realistic")
    assert load_plant("ideal").enabled == () == plant.ideal().enabled
    assert plant.only("thermal").enabled == ("thermal",)
    assert plant.only("thermal").thermal.temperature_coefficient_per_K == 0.00393
    with pytest.raises(InvalidInputError, match="effects"):
        plant.only("wind")


def test_a_users_file_loads_and_an_unknown_key_is_named(tmp_path: Path) -> None:
    """A copy of the preset loads from a path; an extra key is a ConfigError naming the section."""
    text = shipped("plant", "realistic").read_text()
    good = tmp_path / "mine.yaml"
    good.write_text(text)
    assert load_plant(str(good)).name == "mine"
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("thermal:\n  enabled: true", "thermal:\n  enabled: true\n  colour: 3"))
    with pytest.raises(ConfigError, match=r"thermal.*colour"):
        load_plant(str(bad))


@pytest.mark.parametrize(
    ("build", "field"),
    [
        (lambda: DriveTrain(True, 2.0, 0.0, 100.0), "drive_train.damping_ratio"),
        (lambda: DriveTrain(True, 0.05, 0.0, -1.0), "drive_train.rod_side_mass_kg"),
        (lambda: CurrentLoop(True, 8e3, 3e3, 0.0, 565.0), "current_loop.bandwidth_Hz"),
        (lambda: CurrentLoop(True, 8e3, 500.0, 2e-5, 565.0), "current_loop.dead_time_s"),
        (lambda: Sensors(True, 2, 0.1, 0.2, 1e-3), "sensors.encoder_counts_per_rev"),
        (lambda: Sensors(True, 4096, 0.1, 0.2, 1.0), "sensors.delay_s"),
        (lambda: Mismatch(True, 0.1, (0.0, 0.0, 5.0), 0.0, 0.0, 0.0), "mismatch.end_mass_com_offset_m[2]"),
        (lambda: Mismatch("yes", 0.1, (0.0, 0.0, 0.0), 0.0, 0.0, 0.0), "mismatch.enabled"),  # type: ignore[arg-type]
    ],
)
def test_out_of_range_values_name_their_field(build, field: str) -> None:  # type: ignore[no-untyped-def]
    """Each section rejects a value out of range with an InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as error:
        build()
    assert error.value.field == field


def test_a_rod_side_mass_below_the_stability_bound_is_rejected() -> None:
    """rod_side_mass_kg < k_s h^2 / 2 at the physics step is named, with the bound (94 kg for 1.87e8 N/m at 1 ms)."""
    train = dataclasses.replace(load_plant("realistic").drive_train, rod_side_mass_kg=50.0)
    with pytest.raises(InvalidInputError, match=r"rod_side_mass_kg.*93\.5"):
        train.check_step(1e-3, 1.87e8)
    train.check_step(5e-4, 1.87e8)  # 23 kg suffices at half the step


@pytest.mark.parametrize(
    ("before", "line", "field", "owner"),
    [
        (
            "  damping_ratio:",
            "  axial_stiffness_N_per_m: 1.87e8",
            "drive_train.axial_stiffness_N_per_m",
            "drive_stiffness",
        ),
        ("  dead_time_s:", "  threshold_voltage_V: 1.0", "current_loop.threshold_voltage_V", "drive_losses"),
    ],
    ids=["stiffness", "inverter_losses"],
)
def test_a_plant_file_that_sets_what_the_emla_file_owns_is_refused_in_one_line(
    tmp_path: Path, before: str, line: str, field: str, owner: str
) -> None:
    """A plant file setting the drive stiffness or an inverter loss is refused in one line: the EMLA file owns it.

    The line names the field and the EMLA file's section (drive_stiffness, drive_losses).
    """
    text = shipped("plant", "realistic").read_text()
    bad = tmp_path / "old.yaml"
    bad.write_text(text.replace(before, f"{line}\n{before}", 1))
    with pytest.raises(ConfigError) as error:
        load_plant(str(bad))
    message = str(error.value)
    assert field in message and owner in message
    assert "\n" not in message

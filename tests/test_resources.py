"""The one resolver of "preset name or path" and the one loader of shipped files."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from hiab_sim.cli import main
from hiab_sim.crane.loader import load_crane
from hiab_sim.errors import ConfigError
from hiab_sim.resources import Kind, locate, shipped, shipped_names
from hiab_sim.study.spec.study_file import load_study, study_from_dict

REPO = Path(__file__).resolve().parents[1]


def test_preset_name_resolves_to_the_shipped_file() -> None:
    """``xs031`` is the shipped crane preset, whose text is that of hiab_sim/presets/hiab_xs031.yaml."""
    found = locate("xs031", "crane")
    assert found.shipped and found.label == "xs031"
    assert found.read_text() == (REPO / "hiab_sim" / "presets" / "hiab_xs031.yaml").read_text(encoding="utf-8")


def test_every_yaml_in_optimize_is_a_shipped_study_name() -> None:
    """Each YAML file below optimize/ is addressable by its path without suffix, and nothing else is."""
    on_disk = {p.relative_to(REPO / "optimize").with_suffix("").as_posix() for p in (REPO / "optimize").rglob("*.yaml")}
    assert set(shipped_names("study")) == on_disk


def test_shipped_study_by_name_equals_the_study_by_path() -> None:
    """``xs031_spiral`` by name and optimize/xs031_spiral.yaml by path load the same study."""
    by_name = load_study("xs031_spiral")
    by_path = load_study(REPO / "optimize" / "xs031_spiral.yaml")
    assert by_name.reference == by_path.reference and by_name.bounds == by_path.bounds
    assert by_name.crane == by_path.crane and by_name.emlas == by_path.emlas


def test_relative_crane_and_emla_paths_resolve_next_to_a_shipped_study() -> None:
    """seed_scale_spiral names its crane and EMLA files relative to itself; they load from the package data."""
    study = load_study("seed_scale_spiral")
    direct = load_crane(REPO / "optimize" / "xs031_seed_scale_crane.yaml")
    assert study.crane == direct
    assert study.crane_source == "xs031_seed_scale_crane.yaml"
    assert study.emla_source == "emla_seed_scale.yaml"
    assert study.emlas.lift.screw_lead != load_study("xs031_spiral").emlas.lift.screw_lead


def test_relative_path_resolves_next_to_the_study_not_the_working_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A study in folder A naming ``crane.yaml`` reads A/crane.yaml even when the working folder has another."""
    raw = yaml.safe_load(shipped("crane", "xs031").read_text())
    folder = tmp_path / "a"
    folder.mkdir()
    (folder / "crane.yaml").write_text(yaml.safe_dump({**raw, "name": "next to the study"}))
    elsewhere = tmp_path / "cwd"
    elsewhere.mkdir()
    (elsewhere / "crane.yaml").write_text(yaml.safe_dump({**raw, "name": "in the working folder"}))
    monkeypatch.chdir(elsewhere)
    study_doc = yaml.safe_load(shipped("study", "xs031_spiral").read_text())
    study = study_from_dict({**study_doc, "crane": "crane.yaml"}, folder / "study.yaml")
    assert study.crane.name == "next to the study"


def test_missing_file_names_the_source_and_the_shipped_names(tmp_path: Path) -> None:
    """A name that is neither shipped nor a file raises ConfigError naming it, the presets and where it looked."""
    study_doc = yaml.safe_load(shipped("study", "xs031_spiral").read_text())
    with pytest.raises(ConfigError, match=r"crane 'nope\.yaml'.*xs031.*looked for .*/a/nope\.yaml"):
        study_from_dict({**study_doc, "crane": "nope.yaml"}, tmp_path / "a" / "s.yaml")
    with pytest.raises(ConfigError, match="no shipped study named 'nope'"):
        shipped("study", "nope")


def test_optimize_accepts_a_shipped_study_name(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``hiab-sim optimize NAME`` with an unknown name exits 2 with one line listing the shipped studies."""
    assert main(["optimize", "no_such_study", "--out", str(tmp_path / "o"), "--no-video", "--no-figures"]) == 2
    err = capsys.readouterr().err.strip()
    assert "xs031_spiral" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize(
    ("kind", "name", "file"),
    [("machine", "exact", "exact_excavator.yaml"), ("soil", "medium_clay", "soil_medium_clay.yaml")],
)
def test_machines_and_soils_resolve_like_every_kind(tmp_path: Path, kind: Kind, name: str, file: str) -> None:
    """A shipped machine or soil by name, the same file by path, and a missing one named with the shipped names."""
    shipped_file = REPO / "hiab_sim" / "presets" / file
    by_name = locate(name, kind)
    assert by_name.shipped and by_name.read_text() == shipped_file.read_text(encoding="utf-8")
    copy = tmp_path / file
    copy.write_text(shipped_file.read_text(encoding="utf-8"), encoding="utf-8")
    by_path = locate(str(copy), kind)
    assert not by_path.shipped and by_path.read_text() == by_name.read_text()
    assert locate(by_path, kind) is by_path
    with pytest.raises(
        ConfigError, match=rf"cannot read {kind} 'nope': neither a shipped name \(.*{name}.*\)"
    ) as caught:
        locate("nope", kind)
    assert "\n" not in str(caught.value)

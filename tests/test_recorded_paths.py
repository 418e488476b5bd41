"""A result records its study file by an absolute path: the folder can be read from any working directory."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from hiab_sim.study import load_study

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("study", ["xs031_spiral", "exact_grading"])
def test_a_study_given_by_a_relative_path_records_its_absolute_path(
    study: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Loaded as ``optimize/<study>.yaml`` from one folder, the recorded path loads it again from another."""
    (tmp_path / "optimize").mkdir()
    for file in (ROOT / "optimize").glob(f"{study}*"):
        shutil.copy(file, tmp_path / "optimize" / file.name)
    for csv in (ROOT / "optimize").glob("*.csv"):
        shutil.copy(csv, tmp_path / "optimize" / csv.name)
    monkeypatch.chdir(tmp_path)
    loaded = load_study(f"optimize/{study}.yaml")
    assert Path(loaded.path).is_absolute() and Path(loaded.path) == tmp_path / "optimize" / f"{study}.yaml"
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    assert load_study(loaded.path).name == loaded.name


def test_a_shipped_study_records_the_package_file() -> None:
    """A shipped name records the shipped file itself (inside the package or the source tree)."""
    path = Path(load_study("xs031_spiral").path)
    assert path.is_file() and path.name == "xs031_spiral.yaml"

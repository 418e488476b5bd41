"""Run safety: folder ownership, stale outputs, --resume restoring its starts and needing checkpoints."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from test_study_small import small_study, write_study

from hiab_sim.cli import main
from hiab_sim.errors import ConfigError, InvalidInputError
from hiab_sim.study.run_safety import (
    OWNER_FILE,
    check_folder,
    claim_folder,
    owner_record,
    read_owner,
    resolve_starts,
)

#: End-to-end runs of whole studies and commands: the full suite, not the fast tier.
pytestmark = pytest.mark.e2e

FLAGS = ["--no-video", "--quiet", "--no-figures"]
OUTPUTS = (
    "result.json",
    "trajectory.npz",
    "checkpoint_0.json",
    "checkpoint_3.json",
    "objective.png",
    "playback.mp4",
    "simulation.json",
    "summary.md",
)


def _fill(folder: Path, names: tuple[str, ...] = OUTPUTS) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        (folder / name).write_text("old")


def _claim(folder: Path, digest: str, starts: int = 1) -> None:
    claim_folder(folder, owner_record(folder / "s.yaml", "s", digest, starts), resume=False)


def test_a_folder_of_another_study_is_refused_unless_forced(tmp_path: Path) -> None:
    """A marker with another study hash refuses the run (field --out); the same hash and --force pass."""
    _claim(tmp_path, "a" * 64)
    with pytest.raises(ConfigError, match=r"belongs to the study named 's'.*name: field.*--force"):
        check_folder(tmp_path, "b" * 64, resume=False, force=False)
    check_folder(tmp_path, "a" * 64, resume=False, force=False)
    check_folder(tmp_path, "b" * 64, resume=False, force=True)


def test_a_legacy_folder_is_owned_by_its_checkpoints_study(tmp_path: Path) -> None:
    """Without a marker, a checkpoint's study hash decides; a folder with nothing of hiab-sim's is refused."""
    (tmp_path / "checkpoint_0.json").write_text(json.dumps({"study_sha256": "a" * 64, "study": "x.yaml"}))
    with pytest.raises(ConfigError, match=r"belongs to study x\.yaml"):
        check_folder(tmp_path, "b" * 64, resume=False, force=False)
    check_folder(tmp_path, "a" * 64, resume=False, force=False)
    other = tmp_path / "holiday"
    _fill(other, ("notes.txt",))
    with pytest.raises(InvalidInputError, match="holds no hiab-sim result"):
        check_folder(other, "a" * 64, resume=False, force=False)
    check_folder(tmp_path / "new", "a" * 64, resume=False, force=False)  # not there yet: fine


def test_a_folder_of_pictures_or_another_commands_output_is_not_a_result(tmp_path: Path) -> None:
    """Files that match a run's output names (*.png, *.mp4, summary.md) do not make a folder a result folder.

    Without a marker, a checkpoint or result.json the folder is refused, naming what --force would delete;
    a legacy folder with result.json but no marker is still a result folder.
    """
    photos = tmp_path / "photos"
    _fill(photos, ("holiday.png", "movie.mp4", "summary.md"))
    with pytest.raises(InvalidInputError, match=r"holds no hiab-sim result.*--force \(which deletes its holiday"):
        check_folder(photos, "a" * 64, resume=False, force=False)
    assert sorted(p.name for p in photos.iterdir()) == ["holiday.png", "movie.mp4", "summary.md"]
    for legacy in ("result.json", "checkpoint_0.json"):  # a folder written before the marker: a result folder
        _fill(tmp_path / legacy, (legacy, "objective.png"))
        check_folder(tmp_path / legacy, "a" * 64, resume=False, force=False)


def test_a_fresh_run_deletes_every_earlier_output_and_nothing_else(tmp_path: Path) -> None:
    """A fresh claim deletes results, checkpoints, figures and video, keeps other files, writes the marker."""
    _fill(tmp_path, (*OUTPUTS, "notes.txt"))
    removed = claim_folder(tmp_path, owner_record(tmp_path / "s.yaml", "s", "a" * 64, 2), resume=False)
    assert sorted(p.name for p in removed) == sorted(OUTPUTS)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([OWNER_FILE, "notes.txt"])
    assert read_owner(tmp_path) == {
        "study": str((tmp_path / "s.yaml").resolve()),
        "name": "s",
        "study_sha256": "a" * 64,
        "starts": 2,
    }


def test_a_resumed_run_keeps_its_outputs(tmp_path: Path) -> None:
    """claim_folder with resume deletes nothing."""
    _fill(tmp_path)
    assert claim_folder(tmp_path, owner_record(tmp_path / "s.yaml", "s", "a" * 64, 1), resume=True) == []
    assert all((tmp_path / name).is_file() for name in OUTPUTS)


def test_resume_restores_the_runs_own_starts(tmp_path: Path) -> None:
    """--starts as given; else with --resume the marker's starts, else the checkpoint count; else 1."""
    _fill(tmp_path, ("checkpoint_0.json", "checkpoint_1.json", "checkpoint_2.json"))
    assert resolve_starts(tmp_path, None, resume=True) == 3
    claim_folder(tmp_path, owner_record(tmp_path / "s.yaml", "s", "a" * 64, 6), resume=True)
    assert resolve_starts(tmp_path, None, resume=True) == 6
    assert resolve_starts(tmp_path, 2, resume=True) == 2
    assert resolve_starts(tmp_path, None, resume=False) == 1
    with pytest.raises(InvalidInputError, match="--starts"):
        resolve_starts(tmp_path, 0, resume=False)


def test_resume_without_checkpoints_is_an_error(tmp_path: Path) -> None:
    """--resume on a folder without checkpoints (or a typo) raises naming --resume, in both checks."""
    for folder in (tmp_path, tmp_path / "typo"):
        with pytest.raises(InvalidInputError, match=r"--resume .* has no checkpoint"):
            resolve_starts(folder, None, resume=True)
        with pytest.raises(InvalidInputError, match=r"--resume .* has no checkpoint"):
            check_folder(folder, "a" * 64, resume=True, force=False)


@pytest.fixture(scope="module")
def two_start_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small study run with --starts 2."""
    folder = tmp_path_factory.mktemp("safety")
    study = write_study(folder, small_study())
    assert main(["optimize", str(study), "--out", str(folder / "out"), "--starts", "2", *FLAGS]) == 0
    return folder / "out"


def test_cli_resume_restores_two_starts(two_start_run: Path, tmp_path: Path) -> None:
    """Optimize --resume without --starts on a 2-start run reports both starts again."""
    out = tmp_path / "out"
    shutil.copytree(two_start_run, out)
    study = Path(read_owner(out)["study"])  # type: ignore[index]
    assert main(["optimize", str(study), "--out", str(out), "--resume", *FLAGS]) == 0
    result = json.loads((out / "result.json").read_text())
    assert [s["start"] for s in result["multistart"]["starts"]] == [0, 1]


def test_cli_another_study_is_refused_then_forced(two_start_run: Path, tmp_path: Path, capsys) -> None:
    """Another study exits 2 leaving the folder as it was; with --force it runs and no stale output survives."""
    out = tmp_path / "out"
    shutil.copytree(two_start_run, out)
    _fill(out, ("objective.png", "playback.mp4", "simulation.json"))
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    other = write_study(tmp_path, small_study(name="other", tracking={**small_study()["tracking"], "position": 3e-3}))
    capsys.readouterr()
    assert main(["optimize", str(other), "--out", str(out), *FLAGS]) == 2
    err = capsys.readouterr().err
    assert "belongs to the study named 'small'" in err and "out of range" not in err
    assert len(err.strip().splitlines()) == 1
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert main(["optimize", str(other), "--out", str(out), "--force", *FLAGS]) == 0
    names = sorted(p.name for p in out.iterdir())
    expected = [OWNER_FILE, "checkpoint_0.json", "report.html", "result.json", "summary.md", "trajectory.npz"]
    assert names == sorted(expected)
    assert read_owner(out)["name"] == "other"  # type: ignore[index]


def test_cli_resume_with_a_typo_in_out_exits_2(tmp_path: Path, capsys) -> None:
    """Optimize --resume --out <missing folder> exits 2 with one line instead of starting afresh."""
    study = write_study(tmp_path, small_study())
    assert main(["optimize", str(study), "--out", str(tmp_path / "typo"), "--resume", *FLAGS]) == 2
    err = capsys.readouterr().err
    assert "--resume" in err and "no checkpoint" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "typo").exists()

"""``energy-map``, ``pareto`` and ``sweep`` refuse an --out folder holding another command's output (its summary.md)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from test_study_small import TINY, small_study, write_study

from hiab_sim.cli import main
from hiab_sim.sweep.out_folder import check_out_folder


def commands(folder: Path, out: Path) -> dict[str, list[str]]:
    """Each command's arguments on the tiny study, writing into ``out``."""
    study = write_study(folder, small_study(**TINY))
    sweep = folder / "sweep.yaml"
    sweep.write_text(yaml.safe_dump({"study": "study.yaml", "grid": {"payload": [0.0]}}))
    return {
        "energy-map": ["energy-map", str(study), "--grid", "2", "--out", str(out)],
        "pareto": ["pareto", str(study), "--against", "peak_force", "--points", "2", "--out", str(out)],
        "sweep": ["sweep", str(sweep), "--quiet", "--out", str(out)],
    }


@pytest.mark.parametrize(
    ("command", "marker", "owner"),
    [
        ("energy-map", "result.json", "optimize"),
        ("pareto", "result.json", "optimize"),
        ("sweep", "result.json", "optimize"),
        ("energy-map", "owner.json", "optimize"),
        ("sweep", "checkpoint_0.json", "optimize"),  # an optimisation from before owner.json
        ("pareto", "energy_map.json", "energy-map"),
        ("energy-map", "pareto.json", "pareto"),
    ],
)
def test_out_folder_of_another_command_is_refused_and_left_as_it_was(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, marker: str, owner: str
) -> None:
    """Exit 2, one line naming the other command and its file and a subfolder to use; the folder's files unchanged."""
    out = tmp_path / "run"
    out.mkdir()
    (out / marker).write_text("{}\n")
    (out / "summary.md").write_text("the other command's answer\n")
    assert main(commands(tmp_path, out)[command]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert f"--out = '{out}'" in err and f"hiab-sim {owner} ({marker})" in err and f"e.g. {out}/" in err
    assert sorted(p.name for p in out.iterdir()) == sorted([marker, "summary.md"])
    assert (out / "summary.md").read_text() == "the other command's answer\n"


def test_a_commands_own_earlier_output_is_its_folder(tmp_path: Path) -> None:
    """A folder of the command's own earlier output (its marker) is accepted: a re-run replaces it."""
    for marker, command in (("energy_map.json", "energy-map"), ("pareto.json", "pareto"), ("sweep.parquet", "sweep")):
        out = tmp_path / command
        out.mkdir()
        (out / marker).write_text("")
        (out / "summary.md").write_text("")
        check_out_folder(out, command, "sub")

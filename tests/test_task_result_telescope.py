"""result.json ``tasks[k].telescope``: the crane's text on a crane file, absent on a machine file (it has no telescope).

Files written before this rule hold the crane's text for a machine file's task too; they stay readable.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from machine_result_helper import EXCAVATOR_STUDY, excavator_move, solved_study

from hiab_sim.results.codec import from_json
from hiab_sim.results.read import read_result
from hiab_sim.results.schema import Result
from hiab_sim.study.report.weighted import TELESCOPE


@pytest.fixture(scope="module")
def weighted_excavator(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small excavator study as one task of weight 20 (a weighted sum: result.json has ``tasks``), optimised."""
    folder = tmp_path_factory.mktemp("weighted_excavator")
    excavator_move(folder)
    tasks = [{**EXCAVATOR_STUDY["tasks"][0], "weight": 20}]  # type: ignore[index]
    (folder / "study.yaml").write_text(yaml.safe_dump({**EXCAVATOR_STUDY, "tasks": tasks}), encoding="utf-8")
    return solved_study(folder)


def test_a_machine_files_task_result_claims_no_telescope(weighted_excavator: Path) -> None:
    data = json.loads((weighted_excavator / "result.json").read_text(encoding="utf-8"))
    assert len(data["tasks"]) == 1 and "telescope" not in data["tasks"][0]
    assert read_result(weighted_excavator).tasks[0].telescope is None  # type: ignore[index]


def test_an_older_result_with_the_telescope_text_on_a_machine_file_stays_readable(weighted_excavator: Path) -> None:
    data = json.loads((weighted_excavator / "result.json").read_text(encoding="utf-8"))
    task = data["tasks"][0]
    data["tasks"][0] = {**{k: task[k] for k in ("name", "weight", "kind", "duration_s", "payload_kg")}}
    data["tasks"][0] |= {"telescope": TELESCOPE} | task  # the old key order: telescope after payload_kg
    assert from_json(Result, data).tasks[0].telescope == TELESCOPE  # type: ignore[index]

"""Sweep paths: what a path names when it is not there, and a machine file's study, whose bounds are its machine's."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml
from test_study_small import TINY, machine_form, small_study

from hiab_sim.cli import main
from hiab_sim.errors import ConfigError
from hiab_sim.resources import locate
from hiab_sim.study.spec.study_file import study_from_dict
from hiab_sim.sweep.paths import set_path
from hiab_sim.sweep.spec import load_sweep


def write(folder: Path, study: dict[str, Any], grid: dict[str, Any]) -> Path:
    """Write the study and a sweep file over it; return the sweep file."""
    (folder / "study.yaml").write_text(yaml.safe_dump(study))
    path = folder / "sweep.yaml"
    path.write_text(yaml.safe_dump({"study": "study.yaml", "grid": grid}, sort_keys=False))
    return path


def test_an_index_below_a_missing_key_names_that_key() -> None:
    """``a.b.c[0]`` where ``a`` has no ``b`` says ``a.b`` is not there; an index past a list's end gives its length."""
    with pytest.raises(ConfigError, match=r"^a\.b\.c\[0\]: a\.b is not in the file, so it has no item \[0\]; "):
        set_path({"a": {}}, "a.b.c[0]", 1.0)
    with pytest.raises(ConfigError, match=r"^a\.v\[3\]: a\.v has 2 items, \[0\] to \[1\]$"):
        set_path({"a": {"v": [1.0, 2.0]}}, "a.v[3]", 1.0)


def test_machine_study_chain_bounds_are_refused_naming_the_machine_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``bounds.lift.up[0]`` on a machine file's study: one line, exit 2, naming where the bounds are and the way.

    The way it names works: a sweep over ``machine`` with a copy of the machine file moves the bounds.
    """
    study = machine_form(small_study(**TINY))
    path = write(tmp_path, study, {"bounds.lift.up[0]": [1.2, 1.25]})
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "bounds.lift.up[0]: a machine file's study has no bounds.lift" in err
    assert "machine file xs031 (chains.<chain>.variables.<variable>.bounds; chains lift, tilt)" in err
    assert "sweep machine over copies of that file" in err
    assert not (tmp_path / "out").exists()
    text = Path(str(locate("xs031", "machine").file)).read_text()
    narrow = "L: {kind: hinge_distance, pivot: base, bounds: [0.80, 1.20]}"
    copy = text.replace("L: {kind: hinge_distance, pivot: base, bounds: [0.80, 1.25]}", narrow)
    assert copy != text
    (tmp_path / "narrow.yaml").write_text(copy)
    sweep = load_sweep(write(tmp_path, study, {"machine": ["xs031", "narrow.yaml"]}))
    up = [study_from_dict(dict(p.study), sweep.study_file).bounds.xi_up[0] for p in sweep.points]
    assert up == [1.25, 1.20]


def test_an_item_of_a_default_list_says_to_give_the_list_or_sweep_it_whole(tmp_path: Path) -> None:
    """``bounds.joint_velocity[0]`` on a crane study that leaves it to its default: give it, or sweep it whole.

    Both ways work: the list given in the study takes the item, the whole list is swept as it is.
    """
    crane = small_study(**TINY)
    assert "joint_velocity" not in crane["bounds"]
    with pytest.raises(ConfigError) as info:
        load_sweep(write(tmp_path, crane, {"bounds.joint_velocity[0]": [0.5, 0.55]}))
    assert str(info.value) == (
        "bounds.joint_velocity[0]: bounds.joint_velocity is not in the file, so it has no item [0]; to sweep one "
        "item, give bounds.joint_velocity in the file (its default, if it has one), or sweep bounds.joint_velocity "
        "as a whole"
    )
    given = {**crane, "bounds": {**crane["bounds"], "joint_velocity": [0.6, 0.6, 0.5]}}
    for study, grid in (
        (given, {"bounds.joint_velocity[0]": [0.5, 0.55]}),
        (crane, {"bounds.joint_velocity": [[0.5, 0.6, 0.5], [0.55, 0.6, 0.5]]}),
    ):
        sweep = load_sweep(write(tmp_path, study, grid))
        limits = [study_from_dict(dict(p.study), sweep.study_file).bounds.joint_velocity for p in sweep.points]
        assert limits == [(0.5, 0.6, 0.5), (0.55, 0.6, 0.5)]


def test_machine_study_refuses_only_its_chains_bounds(tmp_path: Path) -> None:
    """On a machine file's study only ``bounds.<chain>`` (a chain of its machine) names the machine file.

    ``bounds.lift`` whole is refused like ``bounds.lift.up[0]``; ``bounds.boom.up[0]`` (no chain of the
    XS 031) and ``bounds.triangle_margin_deg[0]`` (not a list) get the path's own message, and
    ``bounds.joint_velocity[0]`` (a list the study gives) is swept.
    """
    study = machine_form(small_study(**TINY))
    with pytest.raises(ConfigError, match=r"^bounds\.lift: a machine file's study has no bounds\.lift: "):
        load_sweep(write(tmp_path, study, {"bounds.lift": [{"low": [0.8, 0.04, 0.6], "up": [1.2, 0.3, 1.0]}]}))
    for path, message in (
        ("bounds.boom.up[0]", "bounds.boom.up[0]: bounds.boom is not in the file, so it has no item [0]; "),
        ("bounds.triangle_margin_deg[0]", "bounds.triangle_margin_deg[0]: bounds.triangle_margin_deg is not in "),
    ):
        with pytest.raises(ConfigError) as info:
            load_sweep(write(tmp_path, study, {path: [1.0]}))
        assert str(info.value).startswith(message) and "machine file" not in str(info.value)
    sweep = load_sweep(write(tmp_path, study, {"bounds.joint_velocity[0]": [0.5, 0.55]}))
    limits = [study_from_dict(dict(p.study), sweep.study_file).bounds.joint_velocity[0] for p in sweep.points]
    assert limits == [0.5, 0.55]

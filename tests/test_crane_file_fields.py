"""Every field of the crane file is validated when the crane loads: a bad value names its field."""

from __future__ import annotations

import copy
import math
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from hiab_sim.crane.loader import crane_from_dict
from hiab_sim.errors import HiabSimError
from hiab_sim.resources import shipped

RAW = yaml.safe_load(shipped("crane", "xs031").read_text())


def _numeric_leaves(node: Any, path: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    """Paths of every number in the parsed crane file (mappings and lists walked)."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _numeric_leaves(value, (*path, key))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield from _numeric_leaves(value, (*path, index))
    elif isinstance(node, int | float) and not isinstance(node, bool):
        yield path


def _with(path: tuple[Any, ...], value: object) -> dict[str, Any]:
    data = copy.deepcopy(RAW)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data


LEAVES = list(_numeric_leaves(RAW))


def _field_named(message: str, path: tuple[Any, ...]) -> bool:
    """The message names the leaf's key (or the list that holds it)."""
    names = [str(k) for k in path if not isinstance(k, int)]
    return names[-1] in message


def test_the_crane_file_has_numeric_fields_to_check() -> None:
    """The walk finds the file's numbers (a guard against a walk that finds nothing)."""
    assert len(LEAVES) > 50
    assert ("hydraulic_cylinders", "lift", "pin_to_pin_at_zero") in LEAVES


@pytest.mark.parametrize("path", LEAVES, ids=lambda p: ".".join(map(str, p)))
@pytest.mark.parametrize("bad", [math.nan, "abc"], ids=["nan", "text"])
def test_nan_or_text_in_any_numeric_field_is_rejected_naming_it(path: tuple[Any, ...], bad: object) -> None:
    """NaN or a word in place of any number of the crane file raises a one-line error naming the field."""
    with pytest.raises(HiabSimError) as error:
        crane_from_dict(_with(path, bad), "crane.yaml")
    message = str(error.value)
    assert "\n" not in message
    assert _field_named(message, path), message


SIZES = [
    p for p in LEAVES if p[0] == "hydraulic_cylinders" and p[-1] in {"bore", "rod", "stroke", "pin_to_pin_at_zero"}
]


@pytest.mark.parametrize("path", SIZES, ids=lambda p: ".".join(map(str, p)))
@pytest.mark.parametrize("bad", [0.0, -0.05])
def test_non_positive_hydraulic_cylinder_size_is_rejected_naming_it(path: tuple[Any, ...], bad: float) -> None:
    """A zero or negative bore, rod, stroke or pin-to-pin length of a hydraulic cylinder names its field."""
    with pytest.raises(HiabSimError) as error:
        crane_from_dict(_with(path, bad), "crane.yaml")
    assert ".".join(map(str, path)) in str(error.value)


@pytest.mark.e2e
def test_cli_rejects_a_nan_cylinder_length_with_exit_2_and_writes_nothing(tmp_path: Path) -> None:
    """``hiab-sim mjcf --crane`` with ``pin_to_pin_at_zero: .nan`` exits 2, one line, no file written."""
    crane = tmp_path / "crane.yaml"
    crane.write_text(yaml.safe_dump(_with(("hydraulic_cylinders", "lift", "pin_to_pin_at_zero"), math.nan)))
    out = tmp_path / "model.xml"
    result = subprocess.run(
        [sys.executable, "-m", "hiab_sim", "mjcf", "--crane", str(crane), "-o", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert "pin_to_pin_at_zero" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert not out.exists()

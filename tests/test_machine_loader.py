"""Bad machine files raise one-line errors that name the field; good ones load as the documented dataclasses."""

from __future__ import annotations

import copy
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from hiab_sim.errors import ConfigError, HiabSimError, InvalidInputError
from hiab_sim.machine.loader import load_machine, machine_from_dict


def _preset(name: str) -> dict[str, Any]:
    text = (resources.files("hiab_sim") / "presets" / name).read_text(encoding="utf-8")
    data = yaml.safe_load(text)
    assert isinstance(data, dict)
    return data


EXCAVATOR = _preset("exact_excavator.yaml")


def _set(path: str, value: Any) -> Callable[[dict[str, Any]], None]:
    """An edit that sets a dotted path of the file to a value."""

    def edit(data: dict[str, Any]) -> None:
        *parents, last = path.split(".")
        node = data
        for key in parents:
            node = node[key]
        node[last] = value

    return edit


def _bad(
    what: str, path: str, value: Any, field: str | None = None, error: type[HiabSimError] = InvalidInputError
) -> tuple[str, Callable[[dict[str, Any]], None], type[HiabSimError], str]:
    """A defect: its label, the edit setting ``path`` to ``value``, the error and the field its message names."""
    return what, _set(path, value), error, path if field is None else field


BAD_FILES: list[tuple[str, Callable[[dict[str, Any]], None], type[HiabSimError], str]] = [
    _bad("unknown parent link", "links.arm.parent", "stick"),
    _bad("chain drives an unknown joint", "chains.arm.joint", "theta9"),
    _bad("pivot on a missing link", "chains.boom.pivots.base.link", "turret"),
    _bad("pivot on a non-adjacent link", "chains.boom.pivots.base.link", "bucket"),
    _bad("duplicate joint name", "links.arm.joint", "alpha"),
    _bad("two chains on one joint", "chains.arm.joint", "alpha"),
    # the EMLA names are the study's actuator names (results, EMLA file): two chains cannot share one
    _bad("two chains name one EMLA", "chains.arm.actuator.emla", "boom"),
    _bad("NaN inertia", "links.arm.bodies.arm.inertia_zz", float("nan")),
    _bad("negative inertia", "links.arm.bodies.arm.inertia_zz", -1.0),
    _bad("negative mass", "links.boom.bodies.boom.mass", -2.0),
    _bad(
        "non-physical 3D inertia",
        "chains.arm.actuator.cylinder_body.inertia",
        [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 1.0]],
    ),
    _bad("stroke shorter than the range needs", "chains.arm.actuator.stroke", 0.45),
    _bad("loop that cannot close", "chains.bucket.linkage.rocker_length", 0.05, field="chains.bucket"),
    _bad("working range through a toggle", "links.boom.joint_range", [-0.4737, 2.9]),
    _bad("unknown key", "chains.arm.actuator.strok", 0.5, field="chains.arm.actuator", error=ConfigError),
    _bad("a word for a number", "gravity", "nine", error=ConfigError),
    _bad("unknown chain kind", "chains.arm.kind", "scissor"),
    _bad("variable bound upside down", "chains.arm.variables.L.bounds", [1.5, 1.1]),
    _bad("variable outside its bounds", "chains.arm.variables.L.bounds", [1.4, 1.5], field="chains.arm.variables.L"),
    _bad("unknown hydraulic cylinder", "chains.arm.actuator.hydraulic_cylinder", "stick", field="hydraulic.cylinders"),
    _bad(
        "revolute axis out of the plane",
        "links.arm.joint_frame",
        {"r": [2.05, 0.0], "R": [[1, 0, 0], [0, 0, -1], [0, 1, 0]]},
        field="links.arm.joint_frame.R",
    ),
    _bad("realistic plant that does not exist", "realistic_plant", "no_such_plant", error=ConfigError),
    _bad("realistic plant not a name", "realistic_plant", {"file": "x"}, error=ConfigError),
]


@pytest.mark.parametrize(("what", "edit", "error", "field"), BAD_FILES, ids=[b[0] for b in BAD_FILES])
def test_bad_machine_file_names_the_field_in_one_line(
    what: str, edit: Callable[[dict[str, Any]], None], error: type[HiabSimError], field: str
) -> None:
    """Each defect raises its error type with a one-line message that starts with (or names) the field."""
    data = copy.deepcopy(EXCAVATOR)
    edit(data)
    with pytest.raises(error) as caught:
        machine_from_dict(data, "exact_excavator.yaml")
    message = str(caught.value)
    assert "\n" not in message
    assert field in message, (what, message)


def test_duplicate_link_name_is_refused(tmp_path: Path) -> None:
    """Two links of one name in the YAML mapping are an error, not a silent overwrite."""
    text = (resources.files("hiab_sim") / "presets" / "exact_excavator.yaml").read_text(encoding="utf-8")
    duplicated = text.replace("  arm:\n    parent: boom", "  boom:\n    parent: boom", 1)
    assert duplicated != text
    path = tmp_path / "dup.yaml"
    path.write_text(duplicated, encoding="utf-8")
    with pytest.raises(ConfigError, match="duplicate name 'boom'"):
        load_machine(path)


def test_a_duplicate_key_is_named_with_its_file_line_and_mapping(tmp_path: Path) -> None:
    """The one line names the file, the key's line and the dotted path of the mapping that holds it twice."""
    text = (resources.files("hiab_sim") / "presets" / "exact_excavator.yaml").read_text(encoding="utf-8")
    duplicated = text.replace("  arm:\n    parent: boom", "  boom:\n    parent: boom", 1)
    line = duplicated.splitlines().index("  boom:", duplicated.splitlines().index("  boom:") + 1) + 1
    path = tmp_path / "dup.yaml"
    path.write_text(duplicated, encoding="utf-8")
    with pytest.raises(ConfigError) as caught:
        load_machine(path)
    assert str(caught.value) == f"{path}: line {line}: duplicate name 'boom' in links"
    nested = text.replace("    parent: boom\n", "    parent: boom\n    parent: boom\n", 1)
    path.write_text(nested, encoding="utf-8")
    with pytest.raises(ConfigError, match=r"dup\.yaml: line \d+: duplicate name 'parent' in links\.\w+$"):
        load_machine(path)


def test_missing_file_and_unknown_preset_are_config_errors(tmp_path: Path) -> None:
    """A path that does not exist and a name that is not shipped are one-line ConfigErrors."""
    for source in (str(tmp_path / "nope.yaml"), "no_such_machine"):
        with pytest.raises(ConfigError) as caught:
            load_machine(source)
        assert "\n" not in str(caught.value)


def test_planar_inertia_becomes_a_thin_plate_and_parts_combine() -> None:
    """inertia_zz gives diag(Izz/2, Izz/2, Izz); a link's parts combine by the parallel-axis theorem."""
    machine = load_machine("exact")
    arm = machine.link("arm").parts[0]
    assert arm.planar_only
    np.testing.assert_allclose(arm.inertia, np.diag([15.129, 15.129, 30.258]))
    boom = load_machine("xs031").link("lift_boom")
    a, b = boom.parts
    total = boom.body
    assert total is not None
    assert total.mass == pytest.approx(a.mass + b.mass)
    com = (a.mass * np.asarray(a.com) + b.mass * np.asarray(b.com)) / (a.mass + b.mass)
    np.testing.assert_allclose(total.com, com)
    # Izz about the combined centre: each part's own Izz plus m d^2 in the plane (hand parallel-axis sum)
    izz = sum(p.inertia_zz + p.mass * float(np.sum((np.asarray(p.com)[:2] - com[:2]) ** 2)) for p in (a, b))
    assert total.inertia_zz == pytest.approx(izz, rel=1e-14)


def test_design_moves_pivots_as_declared() -> None:
    """hinge_distance slides the pivot along its line to the hinge; pivot_x/y set coordinates; x0 sets Lc = x0 - Lc0."""
    machine = load_machine("exact")
    values = machine.design_values()
    keys = machine.variable_keys
    values[keys.index("arm.L")] = 1.2
    values[keys.index("bucket.Gx")] = -0.1
    values[keys.index("bucket.x0")] = 0.8
    designed = machine.with_design(values)
    hinge = np.array([2.05, 0.0])
    old, new = machine.chain("arm").pivot("base").xy, designed.chain("arm").pivot("base").xy
    assert np.linalg.norm(new - hinge) == pytest.approx(1.2)
    a, b = old - hinge, new - hinge
    assert a[0] * b[1] - a[1] * b[0] == pytest.approx(0.0, abs=1e-15)
    assert designed.chain("bucket").pivot("base").position == (-0.1, 0.32, 0.0)
    act = designed.chain("bucket").actuator
    assert act.retracted_length == pytest.approx(0.8)
    assert act.piston_offset == machine.chain("bucket").actuator.piston_offset
    np.testing.assert_allclose(designed.design_values(), values, atol=1e-15)


@settings(max_examples=30, deadline=None)
@given(fractions=st.lists(st.floats(0.0, 1.0), min_size=9, max_size=9), preset=st.sampled_from(["xs031", "exact"]))
def test_design_values_round_trip_through_with_design(fractions: list[float], preset: str) -> None:
    """Any values inside the declared bounds come back from with_design(values).design_values() to 1e-12."""
    machine = _MACHINES[preset]
    low, high = machine.design_bounds()
    values = low + np.asarray(fractions[: low.size]) * (high - low)
    np.testing.assert_allclose(machine.with_design(values).design_values(), values, rtol=0, atol=1e-12)


_MACHINES = {name: load_machine(name) for name in ("xs031", "exact")}

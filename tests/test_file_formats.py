"""The file-format reference names exactly the keys the loaders accept: probed against every loader."""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import replace

import pytest

from hiab_sim.docs_site.field_specs import KEYS, Key
from hiab_sim.docs_site.field_specs.study import study_keys
from hiab_sim.docs_site.file_formats import discrepancies, file_formats_markdown, key_name
from hiab_sim.docs_site.formats import FORMATS
from hiab_sim.docs_site.probe import container, split
from hiab_sim.errors import ConfigError, HiabSimError


@pytest.mark.parametrize("name", sorted(FORMATS))
def test_reference_documents_every_key_the_loader_accepts_and_no_other(name: str) -> None:
    """At every documented mapping, the documented keys equal the keys the loader accepts (probed)."""
    assert discrepancies(name) == []


def test_a_key_the_loader_rejects_or_an_undocumented_key_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """Documenting a key the study loader rejects, or dropping one it accepts, makes the comparison fail."""
    rows = KEYS["study"]()
    dropped = [k for k in rows if k.path != "grid.fine_factor"]
    monkeypatch.setitem(KEYS, "study", lambda: [*dropped, Key("grid.substeps", type="integer")])
    found = discrepancies("study")
    assert any("'fine_factor'" in line and "does not document" in line for line in found)
    assert any("'substeps'" in line and "rejects" in line for line in found)


def test_a_fixed_key_beside_names_is_checked_against_the_loader(monkeypatch: pytest.MonkeyPatch) -> None:
    """Under the machine form's ``mounting`` (actuator names, two settings) a setting the loader rejects is caught."""
    rows = KEYS["study"]()
    monkeypatch.setitem(KEYS, "study", lambda: [*rows, Key("mounting.margin", type="number", form="machine")])
    found = discrepancies("study")
    assert found == ["study (machine form): mounting: names from another file; the loader rejects 'margin'"], found


def test_a_key_documented_for_the_wrong_form_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """`tracked` documented for the crane form only: the machine form's documents hold it and load, so it is reported.

    The study's keys are compared per form (crane file or machine file), not over the union of the forms.
    """
    rows = [replace(k, form="crane") if k.path == "tracked" else k for k in KEYS["study"]()]
    monkeypatch.setitem(KEYS, "study", lambda: rows)
    found = discrepancies("study")
    assert any(line.startswith("study (machine form): top level") and "'tracked'" in line for line in found), found
    machine_only = [k for k in KEYS["study"]() if k.form == "machine"]
    assert {k.path for k in machine_only} >= {"machine", "initial_lengths", "bounds.joint_velocity"}


def test_reference_rows_take_defaults_and_ranges_from_the_dataclasses() -> None:
    """The study's spline and tracking rows carry the dataclasses' defaults and their __post_init__ ranges."""
    rows = {k.path: k for k in study_keys()}
    assert rows["spline.degree"].default == "5" and rows["spline.degree"].allowed == "[3, 7] (integer)"
    assert rows["tracking.position"].unit == "m" and rows["tracking.position"].allowed == "> 0"
    assert rows["solver.method"].allowed == "one of `slsqp`, `ipopt`"


def test_the_page_lists_every_documented_key() -> None:
    """Every documented key path of every format is a row of the generated page."""
    page = file_formats_markdown()
    for name in FORMATS:
        for key in KEYS[name]():
            assert f"| `{key.path}`" in page, key.path


def test_a_free_mapping_is_reported_when_documented_as_a_section(monkeypatch: pytest.MonkeyPatch) -> None:
    """A mapping whose keys the loader does not restrict (the crane's bodies) must be documented as free."""
    rows = [replace(k, kind="section") if k.path == "bodies" else k for k in KEYS["crane"]()]
    monkeypatch.setitem(KEYS, "crane", lambda: rows)
    assert any("bodies: the loader accepts any key" in line for line in discrepancies("crane"))


def _without(document: dict, path: str) -> dict | None:
    """A copy of ``document`` without the key at ``path`` (None: the document has no such key)."""
    trial = copy.deepcopy(document)
    *above, last = split(path)
    try:
        node = container(trial, ".".join(above))
    except KeyError:
        return None
    name = key_name(last)
    if name.startswith("<") or name not in node:
        return None
    del node[name]
    return trial


def _missing(load: Callable[[object], object], document: dict) -> str | None:
    """The loader's missing-key message for ``document``, or None when it names no missing key."""
    try:
        load(document)
    except ConfigError as error:
        return str(error) if "missing key" in str(error) else None
    except HiabSimError:
        return None  # a range or assembly failure: the key itself may be left out
    return None


def test_machine_keys_documented_as_required_are_the_ones_the_loader_needs() -> None:
    """A machine key documented `required`, dropped from a shipped file, is a missing key; one with a default is not.

    The loader, not the reference, decides which keys a file may leave out.
    """
    fmt = FORMATS["machine"]
    checked = 0
    for key in KEYS["machine"]():
        if key.kind == "free" or key.default.startswith(("required for", "exactly one")):
            continue  # conditional: required for some chains or links only
        required = key.default in ("", "required")
        for document in fmt.documents():
            trial = _without(document, key.path)
            if trial is None:
                continue
            message = _missing(fmt.load, trial)
            if required:
                assert message is not None and repr(key_name(split(key.path)[-1])) in message, key.path
            else:
                assert message is None, (key.path, message)
            checked += 1
    assert checked > 80, checked  # 110 (key, document) pairs in the shipped machines

"""The file-format reference names exactly the keys the loaders accept: probed against every loader."""

from __future__ import annotations

from dataclasses import replace

import pytest

from hiab_sim.docs_site.field_specs import KEYS, Key
from hiab_sim.docs_site.field_specs.study import study_keys
from hiab_sim.docs_site.file_formats import discrepancies, file_formats_markdown
from hiab_sim.docs_site.formats import FORMATS


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

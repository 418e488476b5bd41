"""validate/update_readme.py --check: a stale table of docs/validation.md fails, round-off-level changes do not."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _module() -> ModuleType:
    spec = importlib.util.spec_from_file_location("update_readme", ROOT / "validate" / "update_readme.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


TABLE = (
    "| case | samples | error [N] | pass |\n"
    "|---|---:|---:|:---:|\n"
    "| static | 500 | 1.86e-09 | yes |\n"
    "| moving | 1001 | 0.00e+00 | yes |\n"
    "\nTolerances: force errors <= 1e-06.\n"
)


def _check(tmp_path: Path, fresh: str) -> int:
    module = _module()
    readme = tmp_path / "README.md"
    readme.write_text(f"intro\n{module.START}\n{TABLE}{module.END}\noutro\n")
    table = tmp_path / "table.md"
    table.write_text(fresh)
    before = readme.read_text()
    status = module.main(["--table", str(table), "--readme", str(readme), "--check"])
    assert readme.read_text() == before  # --check never writes
    return int(status)


def test_the_same_table_passes(tmp_path: Path) -> None:
    """A fresh table identical to the README's passes the check."""
    assert _check(tmp_path, TABLE) == 0


def test_round_off_level_changes_pass(tmp_path: Path) -> None:
    """An error 1.86e-09 -> 1.16e-09 (another CPU's round-off, as measured between two machines) is not stale."""
    assert _check(tmp_path, TABLE.replace("1.86e-09", "1.16e-09")) == 0


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("1.86e-09", "1.86e-07"),  # an error 100x larger
        ("0.00e+00", "1.00e-16"),  # an exact zero that no longer is
        ("| 500 |", "| 400 |"),  # another sample count
        ("| yes |\n\n", "| NO |\n\n"),  # a case that fails now
        ("static", "static+payload"),  # a renamed case
        ("1e-06", "1e-07"),  # another tolerance
        ("| moving | 1001 | 0.00e+00 | yes |\n", ""),  # a case removed
    ],
)
def test_a_stale_table_fails(tmp_path: Path, capsys: pytest.CaptureFixture[str], old: str, new: str) -> None:
    """Changed text, counts, verdicts, tolerances, rows, or numbers more than 10x apart make --check exit 1."""
    assert old in TABLE
    assert _check(tmp_path, TABLE.replace(old, new, 1)) == 1
    assert "is stale" in capsys.readouterr().err


def test_the_validation_page_has_one_validation_table() -> None:
    """docs/validation.md holds the markers once, in order, around the table: its header and 8 passing cases."""
    module = _module()
    readme = (ROOT / "docs" / "validation.md").read_text()
    assert readme.count(module.START) == readme.count(module.END) == 1
    block = module.current_block(readme)
    assert block.startswith("| case | samples |")
    rows = [line for line in block.splitlines() if line.startswith("| ") and not line.startswith("| case")]
    assert len(rows) >= 8 and all(row.endswith("| yes |") for row in rows)

"""The XS 031 optima's reproducibility table of docs/machine.md: recorded runs, the shipped optima, the stated bounds.

``scripts/optimum_reproducibility.py --record`` optimised each crane-file study of the XS 031 as shipped,
with the crane file's gravity one ulp up, and through the machine file; docs/machine.md shows the table
of the recorded numbers. The shipped runs must be the shipped optima (tests/data/shipped_optima.json),
and the page's claims must hold for the recorded numbers.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from script_helper import load_script

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = load_script("optimum_reproducibility", ROOT / "scripts" / "optimum_reproducibility.py")
OPTIMA = load_script("shipped_optima", ROOT / "scripts" / "shipped_optima.py")
RECORDED = json.loads(SCRIPT.RECORD.read_text())


def test_the_page_shows_the_table_of_the_recorded_runs() -> None:
    """docs/machine.md holds the script's table of the recorded numbers, every crane-file XS 031 study a row."""
    assert SCRIPT.table(RECORDED) in (ROOT / "docs" / "machine.md").read_text()
    studies = (ROOT / "optimize").glob("*.yaml")
    crane_studies = {p.stem for p in studies if re.search(r"^crane: xs031\s", p.read_text(), flags=re.M)}
    assert set(RECORDED) == crane_studies


def test_the_shipped_runs_are_the_shipped_optima() -> None:
    """Each study's unchanged run is its recorded optimum: Xi within 1e-8 m, energies 1e-9, the same iterations."""
    for name, runs in RECORDED.items():
        assert OPTIMA.differences(runs["crane"], OPTIMA.expected(name)) == [], name


def test_the_machine_file_moves_an_optimum_no_more_than_three_times_one_ulp_of_gravity() -> None:
    """The page's claim, and on the sharp optima (one ulp moves them < 1e-12 m) the same optimum and iterations."""
    compared = {name: runs for name, runs in RECORDED.items() if "machine" in runs}
    assert len(compared) == len(RECORDED) - 1  # all but the mounting study
    for name, runs in compared.items():
        ulp, _ = SCRIPT.change(runs["ulp"], runs["crane"])
        machine, _ = SCRIPT.change(runs["machine"], runs["crane"])
        assert machine <= 3.0 * max(ulp, 1e-15), name
        if ulp < 1e-12:
            assert machine < 1e-12 and runs["machine"]["iterations"] == runs["crane"]["iterations"], name


def test_the_readme_claim_on_the_default_study_through_the_machine_file_holds() -> None:
    """The README: the default study through the machine file reaches the crane file's optimum within 1e-8 m."""
    runs = RECORDED["xs031_spiral"]
    machine, _ = SCRIPT.change(runs["machine"], runs["crane"])
    assert machine <= 1e-8 and runs["machine"]["iterations"] == runs["crane"]["iterations"]
    readme = " ".join((ROOT / "README.md").read_text().split())
    assert f"optimum (lengths within 1e-8 m, the same {runs['crane']['iterations']} iterations)" in readme

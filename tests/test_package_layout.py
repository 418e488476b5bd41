"""The study package stays laid out by concern: small sub-packages of small modules."""

from __future__ import annotations

from pathlib import Path

import hiab_sim

PACKAGE = Path(hiab_sim.__file__).resolve().parent
#: Most modules (``__init__`` not counted) in one sub-package of ``hiab_sim/study``.
MAX_MODULES = 12
#: Most lines in one module of the package.
MAX_LINES = 400


def test_no_study_sub_package_holds_more_than_twelve_modules() -> None:
    """Each of ``study/``'s sub-packages (spec, nlp, constraints, solvers, ...) has at most 12 modules."""
    sub_packages = [p for p in (PACKAGE / "study").iterdir() if (p / "__init__.py").is_file()]
    assert len(sub_packages) >= 8  # the layout is there to be checked
    counts = {p.name: len([m for m in p.glob("*.py") if m.name != "__init__.py"]) for p in sub_packages}
    assert {name: n for name, n in counts.items() if n > MAX_MODULES} == {}, counts


def test_no_module_of_the_package_is_longer_than_four_hundred_lines() -> None:
    long = {
        str(path.relative_to(PACKAGE)): n
        for path in PACKAGE.rglob("*.py")
        if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES
    }
    assert long == {}

"""The site's navigation: the pages ``mkdocs.yml`` names, plus a section for every other page of ``docs/``.

Other pages (``machine.md``, ``dynamics.md``, ``structure.md``, ``plant.md``, ``energy.md``,
``extending.md``, ``outputs.md``, or any new one, in a subfolder too) land under "Models and checks" when
they exist and the nav names them nowhere, so a page may be added or be absent without editing
``mkdocs.yml`` (and ``mkdocs build --strict`` never fails on a page left out of the nav).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

SECTION = "Models and checks"
#: The order the model pages take when present; other unlisted pages follow alphabetically.
PREFERRED = ("machine.md", "dynamics.md", "structure.md", "plant.md", "energy.md", "extending.md", "outputs.md")


def nav_pages(nav: Any) -> Iterator[str]:
    """Every page path a mkdocs nav names (nested lists and mappings)."""
    if isinstance(nav, str):
        yield nav
    elif isinstance(nav, list):
        for item in nav:
            yield from nav_pages(item)
    elif isinstance(nav, dict):
        for value in nav.values():
            yield from nav_pages(value)


def page_title(path: Path) -> str:
    """The page's first ``# heading``, or its file name in words."""
    for line in path.read_text().splitlines():
        match = re.match(r"#\s+(.+)", line)
        if match:
            return match.group(1).strip().strip("`")
    return path.stem.replace("_", " ").replace("-", " ").capitalize()


def with_model_pages(nav: list[Any], docs_dir: Path) -> list[Any]:
    """``nav`` with a "Models and checks" section of the top-level pages it does not name (none: unchanged)."""
    named = set(nav_pages(nav))
    extra = [p.relative_to(docs_dir).as_posix() for p in docs_dir.rglob("*.md")]
    extra = [p for p in extra if p not in named]
    order = {name: i for i, name in enumerate(PREFERRED)}
    extra.sort(key=lambda p: (order.get(p, len(order)), p.count("/"), p))
    if not extra:
        return nav
    section = {SECTION: [{page_title(docs_dir / p): p} for p in extra]}
    position = next((i for i, item in enumerate(nav) if isinstance(item, dict) and "Reference" in item), len(nav))
    return [*nav[:position], section, *nav[position:]]

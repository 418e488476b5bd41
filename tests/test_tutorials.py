"""Every tutorial runs as written: its files are written, its bash and python blocks executed in order."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

#: End-to-end runs of whole commands (optimize, report, Chromium, tutorials): not in the fast tier.
pytestmark = pytest.mark.e2e

TUTORIALS = Path(__file__).resolve().parents[1] / "docs" / "tutorials"
#: A fenced block: its language, an optional title (a file the block's text is written to) and its text.
BLOCK = re.compile(r'^```(?P<lang>\w+)(?: title="(?P<title>[^"]+)")?\n(?P<body>.*?)^```', re.M | re.S)


def blocks(page: Path) -> list[tuple[str, str | None, str]]:
    """(language, title, text) of each fenced block of ``page``, in order."""
    return [(m["lang"], m["title"], m["body"]) for m in BLOCK.finditer(page.read_text())]


def test_every_tutorial_has_blocks_that_run() -> None:
    """Each tutorial page has at least one bash or python block (so the test below exercises it)."""
    for page in sorted(TUTORIALS.glob("*.md")):
        assert any(lang in ("bash", "python") for lang, _, _ in blocks(page)), page.name


def section_blocks(page: Path, first: str, end: str) -> list[tuple[str, str | None, str]]:
    """(language, title, text) of each fenced block of ``page`` from heading ``first`` to heading ``end``."""
    text = page.read_text()
    assert first in text and end in text, f"{page.name}: no section {first!r} .. {end!r}"
    part = text[text.index(first) : text.index(end)]
    return [(m["lang"], m["title"], m["body"]) for m in BLOCK.finditer(part)]


def run_blocks(
    name: str,
    page_blocks: list[tuple[str, str | None, str]],
    folder: Path,
    languages: tuple[str, ...] = ("bash", "python"),
) -> None:
    """Write the titled blocks as files and run the blocks in ``languages`` in ``folder``, in order; each exits 0."""
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    env.setdefault("MUJOCO_GL", "osmesa")
    for number, (lang, title, body) in enumerate(page_blocks):
        if title is not None:
            (folder / title).write_text(body)
        elif lang in languages:
            command = ["bash", "-euo", "pipefail", "-c", body]
            if lang == "python":  # run as the script file a reader saves it to (multiprocessing imports it again)
                script = folder / f"tutorial_block_{number}.py"
                script.write_text(body)
                command = [sys.executable, str(script)]
            done = subprocess.run(command, cwd=folder, env=env, capture_output=True, text=True, timeout=600)
            assert done.returncode == 0, (
                f"{name}: {lang} block failed:\n{body}\n{done.stdout[-2000:]}{done.stderr[-3000:]}"
            )


@pytest.mark.parametrize("page", sorted(p.name for p in TUTORIALS.glob("*.md")))
def test_tutorial_runs_as_written(page: str, tmp_path: Path) -> None:
    """Titled blocks are written as files, bash and python blocks run in a fresh folder and exit 0."""
    run_blocks(page, blocks(TUTORIALS / page), tmp_path)


#: The own-machine tutorial's machine written from scratch: from this heading to the next section's.
SCRATCH_SECTION = ("## Write the machine file (YAML)", "## The crane file (legacy)")


def test_own_machine_from_scratch_checks_draws_and_optimises(tmp_path: Path) -> None:
    """The own-machine tutorial's machine written from scratch runs as the page shows it: check, show, optimize.

    A boom on a triangle and a telescope on a direct chain: ``machine show`` draws it and ``optimize`` on its CSV
    study converges (about 5 s) with the file's decision variables.
    """
    run_blocks("own-machine.md", section_blocks(TUTORIALS / "own-machine.md", *SCRATCH_SECTION), tmp_path)
    assert (tmp_path / "my_loader.png").read_bytes()[:4] == b"\x89PNG"
    result = json.loads((tmp_path / "runs" / "lift" / "result.json").read_text())
    assert result["solver"]["success"]
    assert result["optimal"]["lengths"]["names"] == ["lift.L", "lift.Lc0", "lift.Lc"]

"""Every tutorial runs as written: its files are written, its bash and python blocks executed in order."""

from __future__ import annotations

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


@pytest.mark.parametrize("page", sorted(p.name for p in TUTORIALS.glob("*.md")))
def test_tutorial_runs_as_written(page: str, tmp_path: Path) -> None:
    """Titled blocks are written as files, bash and python blocks run in a fresh folder and exit 0."""
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    env.setdefault("MUJOCO_GL", "osmesa")
    for number, (lang, title, body) in enumerate(blocks(TUTORIALS / page)):
        if title is not None:
            (tmp_path / title).write_text(body)
        elif lang in ("bash", "python"):
            command = ["bash", "-euo", "pipefail", "-c", body]
            if lang == "python":  # run as the script file a reader saves it to (multiprocessing imports it again)
                script = tmp_path / f"tutorial_block_{number}.py"
                script.write_text(body)
                command = [sys.executable, str(script)]
            done = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
            assert done.returncode == 0, (
                f"{page}: {lang} block failed:\n{body}\n{done.stdout[-2000:]}{done.stderr[-3000:]}"
            )

"""Every subcommand writing into a closed pipe (``hiab-sim crane | head -1``) ends without a traceback."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from hiab_sim.cli import BROKEN_PIPE_STATUS, SUBCOMMANDS

#: End-to-end runs of whole commands (optimize, report, Chromium, tutorials): not in the fast tier.
pytestmark = pytest.mark.e2e


def _into_closed_pipe(*args: str) -> subprocess.CompletedProcess[str]:
    """Run ``python -m hiab_sim ARGS`` with stdout a pipe whose reading end is already closed."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        return subprocess.run(
            [sys.executable, "-m", "hiab_sim", *args],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
            check=False,
        )
    finally:
        os.close(write_end)


@pytest.mark.parametrize("command", [None, *SUBCOMMANDS])
def test_help_into_a_closed_pipe_has_no_traceback(command: str | None) -> None:
    """``hiab-sim [COMMAND] --help`` into a closed pipe: nothing on stderr (argparse ignores the failed write)."""
    done = _into_closed_pipe(*([] if command is None else [command]), "--help")
    assert done.stderr == ""
    assert done.returncode in (0, BROKEN_PIPE_STATUS)


def test_crane_summary_into_a_closed_pipe_has_no_traceback() -> None:
    """The crane summary (a real command's output, not argparse's) into a closed pipe ends quietly."""
    done = _into_closed_pipe("crane")
    assert done.stderr == ""
    assert done.returncode == BROKEN_PIPE_STATUS


def test_every_subcommand_has_a_description() -> None:
    """``hiab-sim COMMAND --help`` explains the command in a sentence, not only its one-line help."""
    from hiab_sim.cli import build_parser

    parser = build_parser()
    actions = [a for a in parser._actions if a.dest == "command"]
    choices = actions[0].choices  # type: ignore[attr-defined]
    for name in SUBCOMMANDS:
        description = choices[name].description or ""
        assert len(description.split()) >= 8, f"{name}: description {description!r}"

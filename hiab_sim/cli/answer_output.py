"""The answer first on the console: a command's summary printed before its details and saved in its folder.

``energy-map``, ``pareto`` and ``sweep`` compute first and print afterwards: the first lines on
stdout are the answer (:func:`publish_answer`), the same text is ``summary.txt`` in the output
folder (written atomically), the details follow after a blank line. Progress goes to stderr only
when both stdout and stderr are terminals (:func:`progress_wanted`): redirected to a file, a bar
or a status line would dump its updates into the log, and on a terminal a status line is wiped
(:class:`StatusLine`) so that the answer still opens what stays on the screen.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from hiab_sim.atomic_io import write_atomic

#: File name of a command's answer inside its output folder.
ANSWER_FILE = "summary.txt"


def progress_wanted(stream: TextIO | None = None) -> bool:
    """True when stdout and ``stream`` (default stderr) are both terminals: only then is progress drawn."""
    stream = sys.stderr if stream is None else stream
    return _isatty(sys.stdout) and _isatty(stream)


def _isatty(stream: TextIO) -> bool:
    isatty = getattr(stream, "isatty", None)
    return bool(isatty()) if callable(isatty) else False


def answer_text(lines: Sequence[str]) -> str:
    """The answer as one text: its lines, each ended by a newline."""
    return "".join(f"{line}\n" for line in lines)


def publish_answer(lines: Sequence[str], folder: Path, details: Sequence[str] = ()) -> Path:
    """Write ``folder/summary.txt`` atomically, print the answer, then a blank line and ``details``; return the file."""
    text = answer_text(lines)
    path = Path(folder) / ANSWER_FILE
    write_atomic(path, text)
    sys.stdout.write(text)
    if details:
        sys.stdout.write("\n" + answer_text(details))
    sys.stdout.flush()
    return path


class StatusLine:
    """One transient line on stderr while a command works (only where :func:`progress_wanted`); wiped on exit."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.shown = progress_wanted()

    def __enter__(self) -> StatusLine:
        if self.shown:
            sys.stderr.write(self.text)
            sys.stderr.flush()
        return self

    def __exit__(self, *_: object) -> None:
        if self.shown:
            sys.stderr.write("\r\033[K")  # back to the line's start, erase it
            sys.stderr.flush()

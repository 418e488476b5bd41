"""Progress on a terminal only: redirected to a file, a bar or a status line would dump its updates into the log.

:func:`progress_wanted` is true when stdout and the progress stream (stderr) are both terminals;
:class:`StatusLine` shows one line on stderr while a command works and wipes it when done, so the
command's answer opens what stays on the screen.
"""

from __future__ import annotations

import sys
from typing import TextIO


def progress_wanted(stream: TextIO | None = None) -> bool:
    """True when stdout and ``stream`` (default stderr) are both terminals: only then is progress drawn."""
    stream = sys.stderr if stream is None else stream
    return _isatty(sys.stdout) and _isatty(stream)


def _isatty(stream: TextIO) -> bool:
    isatty = getattr(stream, "isatty", None)
    return bool(isatty()) if callable(isatty) else False


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

"""The answer first on the console: a command's summary printed before its details and saved in its folder.

``energy-map``, ``pareto`` and ``sweep`` compute first and print afterwards: the first lines on
stdout are the answer (:func:`publish_answer`), the same text is ``summary.md`` in the output
folder (written atomically), the details follow after a blank line. Progress goes to stderr only
on a terminal (:mod:`hiab_sim.terminal`).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

from hiab_sim.atomic_io import write_atomic

#: File name of a command's answer inside its output folder.
ANSWER_FILE = "summary.md"


def answer_text(lines: Sequence[str]) -> str:
    """The answer as one text: its lines, each ended by a newline."""
    return "".join(f"{line}\n" for line in lines)


def publish_answer(lines: Sequence[str], folder: Path, details: Sequence[str] = ()) -> Path:
    """Write ``folder/summary.md`` atomically, print the answer, then a blank line and ``details``; return the file."""
    text = answer_text(lines)
    path = Path(folder) / ANSWER_FILE
    write_atomic(path, text)
    sys.stdout.write(text)
    if details:
        sys.stdout.write("\n" + answer_text(details))
    sys.stdout.flush()
    return path

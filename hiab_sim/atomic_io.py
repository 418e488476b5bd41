"""Atomic file output: write next to the target, then ``os.replace``, so no file is ever half-written."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from hiab_sim.errors import InvalidInputError


@contextlib.contextmanager
def atomic_path(path: Path) -> Iterator[Path]:
    """Yield a temporary path in ``path``'s folder (same suffix); move it onto ``path`` on success.

    The suffix is kept so that writers which pick a format from it (matplotlib, ffmpeg) behave as
    for ``path``. On any exception the temporary file is removed and ``path`` is left untouched.

    Raises:
        InvalidInputError: ``path`` is an existing folder (field ``output path``).

    """
    if path.is_dir():
        raise InvalidInputError("output path", str(path), "must name a file, not an existing folder")
    handle, name = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".part{path.suffix}", dir=path.parent)
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        os.chmod(temporary, 0o644)  # mkstemp creates 0600; results are meant to be shared
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


def write_atomic(path: Path, data: str | bytes) -> None:
    """Write text or bytes to ``path`` atomically, creating its folder if needed."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as temporary:
        temporary.write_bytes(data.encode() if isinstance(data, str) else data)

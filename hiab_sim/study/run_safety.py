"""Run safety: a result folder belongs to one study; fresh runs leave no stale output; resume restores its run.

A run claims its output folder with an ownership marker ``owner.json`` (study path, name, content
hash :func:`hiab_sim.study.solvers.slsqp.study_digest`, number of starts). Rules:

- a folder owned by another study (another content hash) is refused without ``force``; so is a
  non-empty folder that is not a result folder (no ``owner.json``, ``result.json`` or checkpoint: a
  folder of photos, or another command's output such as an energy map, is not one although it
  holds ``*.png`` or ``summary.md``), so that ``--out`` pointing at the wrong place deletes nothing;
- a fresh run (not ``resume``) deletes every output of earlier runs (:data:`OUTPUT_PATTERNS`:
  result, trajectory, checkpoints, summary, figures, videos, the closed-loop simulation's report, copied
  crane) before it writes, so a ``--no-figures`` re-run leaves no old figure beside a new result and no
  simulation of the old design beside the new one; the caller tells the user what was removed;
- ``resume`` needs the folder's checkpoints (a typo in ``--out`` is an error, not a fresh run),
  and restores the run's own number of starts unless it is given; whether the checkpoints are
  this run's is checked per start by :func:`hiab_sim.study.solvers.slsqp.check_checkpoint`.

Only files matching :data:`OUTPUT_PATTERNS` are ever deleted. Checks (:func:`check_folder`,
:func:`resolve_starts`) write nothing; :func:`claim_folder` deletes and writes.
"""

from __future__ import annotations

import json
from numbers import Integral
from pathlib import Path
from typing import Any

from hiab_sim.atomic_io import write_atomic
from hiab_sim.errors import ConfigError, InvalidInputError

OWNER_FILE = "owner.json"
#: Files a run writes into its folder (glob patterns); a fresh run deletes these and nothing else.
OUTPUT_PATTERNS = (
    "result.json",
    "trajectory.npz",
    "checkpoint_*.json",
    "summary.md",
    "*.png",
    "*.mp4",
    "crane.yaml",
    "simulation.json",  # hiab-sim simulate's, of the run it validated
    "report.html",
    "report.pdf",
    OWNER_FILE,
)
NO_CHECKPOINTS = "has no checkpoint_<k>.json to resume from (run without --resume to start afresh)"


def owner_record(study_path: str | Path, name: str, digest: str, starts: int) -> dict[str, Any]:
    """The ownership marker's content: which study owns the folder, and the run's number of starts."""
    return {"study": str(Path(study_path).resolve()), "name": name, "study_sha256": digest, "starts": int(starts)}


def read_owner(folder: Path) -> dict[str, Any] | None:
    """The folder's ownership marker, or None if it has none (an unreadable marker reads as none)."""
    path = folder / OWNER_FILE
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    return data if isinstance(data, dict) else None


def outputs(folder: Path) -> list[Path]:
    """Files in ``folder`` that a run writes (:data:`OUTPUT_PATTERNS`), sorted."""
    if not folder.is_dir():
        return []
    found = {p for pattern in OUTPUT_PATTERNS for p in folder.glob(pattern) if p.is_file()}
    return sorted(found)


def checkpoints(folder: Path) -> list[Path]:
    """The folder's ``checkpoint_<k>.json`` files, sorted."""
    return sorted(folder.glob("checkpoint_*.json")) if folder.is_dir() else []


def _recorded_digest(folder: Path) -> tuple[str | None, str]:
    """The study hash the folder's outputs belong to, and a label of that study (marker, else a checkpoint)."""
    owner = read_owner(folder)
    if owner is not None:
        return owner.get("study_sha256"), f"the study named '{owner.get('name')}' ({owner.get('study')})"
    for path in checkpoints(folder):  # a folder written before the marker existed
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            continue
        if isinstance(data, dict) and "study_sha256" in data:
            return data["study_sha256"], f"study {data.get('study')}"
    return None, "no study"


def check_folder(folder: Path, digest: str, resume: bool, force: bool) -> None:
    """Raise unless this study may use ``folder``; writes nothing.

    A folder of another study raises :class:`ConfigError` naming that study, a bad ``--out`` or
    ``--resume`` :class:`InvalidInputError`. See the module docstring for the rules.
    """
    if folder.exists() and not folder.is_dir():
        raise InvalidInputError("--out", str(folder), "must be a folder (it is a file)")
    if resume:
        if not checkpoints(folder):
            raise InvalidInputError("--resume", str(folder), NO_CHECKPOINTS)
        return  # each checkpoint names its study, ID path and start: check_checkpoint refuses another run's
    if force or not folder.is_dir() or not any(folder.iterdir()):
        return
    recorded, owner = _recorded_digest(folder)
    if recorded is not None and recorded != digest:
        raise ConfigError(
            f"output folder {folder} belongs to {owner}, not to this study (another file or another version of "
            f"it; sha256 {str(recorded)[:12]}); the default folder runs/<name> comes from the study's name: field, "
            "so give this study its own name:, pass --out, or use --force to replace the results there"
        )
    if recorded is None and not (folder / "result.json").is_file() and not checkpoints(folder):
        found = [p.name for p in outputs(folder)]
        deletes = f" (which deletes its {', '.join(found)})" if found else ""
        raise InvalidInputError(
            "--out",
            str(folder),
            "is not empty and holds no hiab-sim result (no owner.json, result.json or checkpoint_<k>.json); "
            f"use another --out, or --force{deletes}",
        )


def check_starts(starts: object, field: str = "starts") -> int:
    """``starts`` as a number of feasible starts, else one line naming ``field``.

    Raises:
        InvalidInputError: not an integer >= 1 (a bool, a float, a string).

    """
    if isinstance(starts, bool) or not isinstance(starts, Integral) or starts < 1:
        raise InvalidInputError(field, starts, "must be an integer >= 1")
    return int(starts)


def resolve_starts(folder: Path, starts: int | None, resume: bool) -> int:
    """The number of starts of a run: as given, else with ``resume`` the run's own, else 1.

    The run's own is the marker's ``starts``, else the number of its checkpoints.

    Raises:
        InvalidInputError: ``starts`` < 1, or ``resume`` on a folder without checkpoints.

    """
    if starts is not None:
        return check_starts(starts, "--starts")
    if not resume:
        return 1
    found = checkpoints(folder)
    if not found:
        raise InvalidInputError("--resume", str(folder), NO_CHECKPOINTS)
    owner = read_owner(folder)
    recorded = owner.get("starts") if owner else None
    if isinstance(recorded, int) and not isinstance(recorded, bool) and recorded >= 1:
        return recorded
    return len(found)


def claim_folder(folder: Path, record: dict[str, Any], resume: bool) -> list[Path]:
    """Make ``folder`` this run's: a fresh run deletes every earlier output; write the marker; return what was deleted.

    Call after :func:`check_folder` and every other input check.
    """
    removed = [] if resume else outputs(folder)
    for path in removed:
        path.unlink(missing_ok=True)
    folder.mkdir(parents=True, exist_ok=True)
    write_atomic(folder / OWNER_FILE, json.dumps(record, indent=2) + "\n")
    return [p for p in removed if p.name != OWNER_FILE]

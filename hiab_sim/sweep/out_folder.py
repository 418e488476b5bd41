"""The output folder of ``energy-map``, ``pareto`` and ``sweep``: refused when another command's output is there.

Each of these commands writes its answer as ``summary.md`` beside its own files
(:mod:`hiab_sim.cli.answer_output`), as ``optimize`` writes its summary into its result folder. In a
folder that holds another command's output the answer would overwrite that command's
``summary.md``, and the two commands' files would share one folder whose lifetimes differ: a fresh
``optimize`` there deletes its own outputs (``summary.md`` and every ``*.png``, the map's and the
front's figures among them) and keeps the map's JSON and NPZ beside a result they no longer
describe. So :func:`check_out_folder` refuses such a folder before anything is computed or written,
and names a subfolder instead. A folder of the same command's earlier output is its own: a re-run
replaces it.
"""

from __future__ import annotations

from pathlib import Path

from hiab_sim.errors import InvalidInputError

#: The files that mark a folder as a command's output: (file name or glob pattern, the command that writes it).
MARKERS = (
    ("result.json", "optimize"),
    ("owner.json", "optimize"),  # an optimisation's claim on its folder, before its result is written
    ("checkpoint_*.json", "optimize"),  # an optimisation's iterations (a folder from before owner.json)
    ("energy_map.json", "energy-map"),
    ("pareto.json", "pareto"),
    ("sweep.parquet", "sweep"),
)


def check_out_folder(out: Path, command: str, instead: str) -> None:
    """Refuse ``out`` if it is a file or holds another command's output; ``instead`` names the subfolder to suggest.

    Raises:
        InvalidInputError: field ``--out``, one line naming the other command, its file and a folder to use.

    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InvalidInputError("--out", str(out), "must be a folder (it is a file)")
    for pattern, owner in MARKERS:
        found = sorted(p.name for p in out.glob(pattern) if p.is_file()) if owner != command else []
        if found:
            raise InvalidInputError(
                "--out",
                str(out),
                f"it holds the output of hiab-sim {owner} ({found[0]}), whose summary.md {command} would overwrite "
                f"with its own: give {command} a folder of its own, e.g. {out / instead}",
            )

"""The one loader of shipped files, and the one resolver of "preset name or path".

Shipped files are read through :mod:`importlib.resources`, so an editable install and a built
wheel behave alike (pyproject.toml maps the top-level folders into the package):

============  ==========================  ===================================================
kind          folder in the source tree   shipped names
============  ==========================  ===================================================
``crane``     ``hiab_sim/presets/``       ``xs031``
``emla``      ``hiab_sim/presets/``       ``default``, ``xs031``, ``paper`` (the seed's), ``exact``
``plant``     ``hiab_sim/presets/``       ``realistic`` (the closed loop's plant effects)
``machine``   ``hiab_sim/presets/``       ``xs031``, ``exact`` (machine files, :mod:`hiab_sim.machine`)
``soil``      ``hiab_sim/presets/``       ``loose_sand``, ``medium_clay``
``study``     ``optimize/``               every ``*.yaml`` by its path without the suffix,
                                          e.g. ``xs031_spiral``, ``sweeps/<name>``
``cases``     ``validate/``               ``cases``
``mjcf``      ``assets/mjcf/``            ``crane_template``
============  ==========================  ===================================================

:func:`locate` turns what a user or a file wrote (``crane: xs031``, ``--cases my.yaml``,
``emla: emla_seed_scale.yaml``) into a :class:`Source`: a shipped name first, else a path;
relative paths resolve next to the file that names them (inside the package data for a shipped
study), else against the working folder.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Literal

from hiab_sim.errors import ConfigError

Kind = Literal["crane", "emla", "study", "cases", "mjcf", "plant", "machine", "soil"]

#: Package (anchor) and sub-folder of each kind's shipped files.
_FOLDERS: dict[str, tuple[str, str]] = {
    "crane": ("hiab_sim", "presets"),
    "emla": ("hiab_sim", "presets"),
    "plant": ("hiab_sim", "presets"),
    "machine": ("hiab_sim", "presets"),
    "soil": ("hiab_sim", "presets"),
    "study": ("hiab_sim._data.studies", ""),
    "cases": ("hiab_sim._data.validate", ""),
    "mjcf": ("hiab_sim._data.mjcf", ""),
}
#: Kinds whose names are given here; the other kinds name every YAML (XML) file of their folder.
_NAMED: dict[str, dict[str, str]] = {
    "crane": {"xs031": "hiab_xs031.yaml"},
    "emla": {
        "default": "emla_xs031.yaml",
        "xs031": "emla_xs031.yaml",
        "paper": "emla_paper.yaml",
        "exact": "emla_exact.yaml",
    },
    "plant": {"realistic": "plant_realistic.yaml", "realistic_exact": "plant_realistic_exact.yaml"},
    "machine": {"xs031": "xs031_machine.yaml", "exact": "exact_excavator.yaml"},
    "soil": {"loose_sand": "soil_loose_sand.yaml", "medium_clay": "soil_medium_clay.yaml"},
}
_SUFFIX = {"mjcf": ".xml"}

#: What each kind is called in messages.
_WHAT = {
    "crane": "crane",
    "emla": "EMLA set",
    "study": "study",
    "cases": "case file",
    "mjcf": "MJCF file",
    "plant": "plant",
    "machine": "machine",
    "soil": "soil",
}

DEFAULT_STUDY = "xs031_spiral"
DEFAULT_CASES = "cases"


@dataclass(frozen=True)
class Source:
    """A file to read: a shipped one (package data) or a user's.

    Attributes:
        label: What reports and messages show: the shipped name or the path as resolved.
        file: The file itself (a :class:`~pathlib.Path` for a user's file).
        shipped: True for package data.

    """

    label: str
    file: Traversable
    shipped: bool

    def read_text(self) -> str:
        """The file's text (UTF-8); a missing or unreadable file raises :class:`ConfigError`."""
        try:
            return self.file.read_text(encoding="utf-8")
        except OSError as error:
            raise ConfigError(f"cannot read {self.label}: {error.strerror or error}") from None

    def read_bytes(self) -> bytes:
        """The file's bytes, e.g. to copy it into a result folder."""
        try:
            return self.file.read_bytes()
        except OSError as error:
            raise ConfigError(f"cannot read {self.label}: {error.strerror or error}") from None

    def sibling(self, relative: str) -> Source:
        """The file ``relative`` to this one's folder (inside the package data for a shipped file)."""
        if self.shipped:
            folder = _folder_of(self.file)
            file = folder.joinpath(*Path(relative).parts)
            return Source(str(file), file, shipped=True)
        path = (Path(str(self.file)).parent / relative).resolve()
        return Source(str(path), path, shipped=False)


def recorded_path(source: Source) -> str:
    """The path a result records for ``source``: a user's file made absolute, a shipped one as it is.

    Absolute, so that a result folder can be read from any working directory (a relative path was
    resolved against wherever the reader ran); a shipped file's own path lies inside the package.
    """
    if source.shipped:
        return str(source.file)
    path = Path(str(source.file))
    return str(path.resolve()) if path.is_file() else str(path)


def _folder_of(file: Traversable) -> Traversable:
    """The folder of a shipped file (package data lies on disk for editable and wheel installs)."""
    parent = getattr(file, "parent", None)
    if parent is None:  # pragma: no cover - only a zip import without .parent
        raise ConfigError(f"cannot resolve a path next to {file}: the package data is not on disk")
    folder: Traversable = parent
    return folder


def shipped_folder(kind: Kind) -> Traversable:
    """The folder of a kind's shipped files."""
    anchor, sub = _FOLDERS[kind]
    folder = resources.files(anchor)
    return folder / sub if sub else folder


def shipped_names(kind: Kind) -> dict[str, Traversable]:
    """Shipped name -> file of a kind (studies: every YAML file below ``optimize/``, sorted)."""
    folder = shipped_folder(kind)
    if kind in _NAMED:
        return {name: folder / file for name, file in _NAMED[kind].items()}
    suffix = _SUFFIX.get(kind, ".yaml")
    found: dict[str, Traversable] = {}

    def walk(node: Traversable, prefix: str) -> None:
        for child in sorted(node.iterdir(), key=lambda c: c.name):
            if child.is_dir() and not child.name.startswith(("_", ".")):
                walk(child, f"{prefix}{child.name}/")
            elif child.is_file() and child.name.endswith(suffix):
                found[prefix + child.name[: -len(suffix)]] = child

    walk(folder, "")
    return found


def shipped(kind: Kind, name: str) -> Source:
    """A shipped file by name; an unknown name raises :class:`ConfigError` listing the known ones."""
    names = shipped_names(kind)
    if name not in names:
        raise ConfigError(f"no shipped {_WHAT[kind]} named {name!r}; shipped: {', '.join(names)}")
    return Source(name, names[name], shipped=True)


def locate(source: str | Path | Source, kind: Kind, relative_to: Source | None = None) -> Source:
    """Resolve a preset or shipped name, or a file path, to a :class:`Source`.

    Order: a :class:`Source` as it is (already located); a shipped name of ``kind`` (a ``str``
    only); an absolute path; a relative path next to ``relative_to`` (the file that names it) when
    given, else against the working folder.

    Raises:
        ConfigError: Neither a shipped name nor an existing file; the message names both options.

    """
    if isinstance(source, Source):
        return source
    if isinstance(source, str):
        names = shipped_names(kind)
        if source in names:
            return Source(source, names[source], shipped=True)
    path = Path(source)
    if path.is_absolute() or relative_to is None:
        candidate = Source(str(path), path, shipped=False)
    else:
        candidate = relative_to.sibling(str(path))
    if not candidate.file.is_file():
        offered = listed_names(kind)
        close = difflib.get_close_matches(str(source), offered, n=1)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        where = f" (looked for {candidate.label})" if str(candidate.label) != str(source) else ""
        raise ConfigError(
            f"cannot read {_WHAT[kind]} '{source}': neither a shipped name ({', '.join(offered)}) "
            f"nor a readable file{where}{hint}"
        )
    return candidate


#: Top-level keys that make a shipped YAML file of the study folder a study (a reference or tasks, and bands).
_STUDY_KEYS = (("tracking",), ("reference", "tasks"))


def listed_names(kind: Kind) -> list[str]:
    """The shipped names offered in messages: for studies only the files that are studies.

    The study folder also ships the EMLA set, crane file and sweep specifications the studies
    name; they resolve as shipped names but are not offered where a study is asked for.
    """
    names = shipped_names(kind)
    if kind != "study":
        return list(names)
    kept = []
    for name, file in names.items():
        keys = {line.split(":", 1)[0] for line in file.read_text(encoding="utf-8").splitlines() if ":" in line}
        if all(any(k in keys for k in group) for group in _STUDY_KEYS):
            kept.append(name)
    return kept


def mjcf_template() -> str:
    """The MJCF template of the crane model (materials, lights, cameras, floor, options)."""
    return shipped("mjcf", "crane_template").read_text()

"""Which keys a loader accepts, found by asking the loader itself.

At every mapping of a file format (a *container* path such as ``bounds.lift`` or ``tasks[].payload``),
:func:`accepted_keys` adds an unknown key to a valid document and runs the loader: its
:class:`~hiab_sim.errors.ConfigError` lists the allowed keys (``unknown key(s) [...]; allowed: [...]``).
Keys a valid document holds and the loader reads without error count as accepted too. The test of the
file-format reference compares these sets with the documented keys, so the reference can name neither
a key the loaders reject nor miss one they accept.

A format with several forms (a study names a crane file or a machine file:
:class:`hiab_sim.docs_site.formats.Form`) is probed per form, on that form's documents only
(:func:`hiab_sim.docs_site.file_formats.discrepancies`).

Path grammar: segments joined by ``.``; ``name[]`` is the first element of a list; ``name{kind}`` a
mapping whose ``kind`` is ``kind``; ``<word>`` any key (the first the document has there).
"""

from __future__ import annotations

import ast
import copy
import re
from collections.abc import Callable, Sequence
from typing import Any

from hiab_sim.errors import ConfigError, HiabSimError

PROBE = "zz_probe_key"
_SEGMENT = re.compile(r"^(?P<name>[^\[\]{}]+)(?P<list>\[\])?(?:\{(?P<kind>[^}]+)\})?$")
_ALLOWED = re.compile(r"unknown key\(s\) (?P<unknown>.+?); allowed: (?P<allowed>.+)$")

Loader = Callable[[Any], object]


def split(path: str) -> list[str]:
    """The segments of a key path (dots inside ``{...}`` kept)."""
    return [s for s in re.split(r"\.(?![^{]*\})", path) if s]


def _descend(node: Any, segment: str, create: bool) -> Any:
    match = _SEGMENT.match(segment)
    if match is None or not isinstance(node, dict):
        raise KeyError(segment)
    name = match.group("name")
    if name.startswith("<"):
        if not node:
            raise KeyError(segment)
        name = next(iter(node))
    if match.group("list"):
        if name not in node or not isinstance(node[name], list) or not node[name]:
            if not create:
                raise KeyError(segment)
            node[name] = [{}]
        child = node[name][0]
    else:
        if name not in node or not isinstance(node[name], dict):
            if not create:
                raise KeyError(segment)
            node[name] = {}
        child = node[name]
    kind = match.group("kind")
    if kind is not None:
        if child.get("kind") != kind:
            if not create:
                raise KeyError(segment)
            child.clear()
        child["kind"] = kind
    return child


def container(document: Any, path: str, create: bool = False) -> Any:
    """The mapping at ``path`` in ``document`` (created on the way with ``create``)."""
    node = document
    for segment in split(path):
        node = _descend(node, segment, create)
    return node


def _parse_keys(text: str) -> set[str]:
    text = text.strip().rstrip(".")
    if text.startswith("["):
        return {str(k) for k in ast.literal_eval(text)}
    return {k.strip() for k in text.split(",") if k.strip()}


def allowed_at(load: Loader, documents: Sequence[Any], path: str) -> set[str] | None:
    """The keys the loader allows at ``path``, from its unknown-key message (None: any key is accepted).

    Raises:
        ConfigError: No document reaches ``path`` with the probe key; the message lists why each failed.

    """
    failures: list[str] = []
    for document in documents:
        for create in (False, True):
            trial = copy.deepcopy(document)
            try:
                node = container(trial, path, create)
            except KeyError:
                continue
            node[PROBE] = 0
            try:
                load(trial)
            except ConfigError as error:
                match = _ALLOWED.search(str(error))
                if match and PROBE in match.group("unknown"):
                    return _parse_keys(match.group("allowed"))
                if PROBE in str(error):  # read as a name (its value is then checked): any key is accepted
                    return None
                failures.append(str(error))
            except HiabSimError as error:  # this document fails elsewhere first: the next one may reach the key
                failures.append(str(error))
            else:
                return None  # a free-form mapping (any key is accepted)
    raise ConfigError(f"no document reaches {path!r} with a probe key: " + " | ".join(failures[:4]))


def present_keys(load: Loader, documents: Sequence[Any], path: str) -> set[str]:
    """Keys at ``path`` in the documents the loader reads without error (a loaded key is an accepted key)."""
    keys: set[str] = set()
    for document in documents:
        try:
            node = container(copy.deepcopy(document), path)
        except KeyError:
            continue
        load(document)
        keys |= {str(k) for k in node}
    return keys


def accepted_keys(load: Loader, documents: Sequence[Any], path: str) -> set[str] | None:
    """Every key the loader accepts at ``path`` (None: a free-form mapping)."""
    allowed = allowed_at(load, documents, path)
    if allowed is None:
        return None
    return allowed | present_keys(load, documents, path)

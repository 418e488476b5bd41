"""The file-format reference page and its check against the loaders.

:func:`file_formats_markdown` writes one table per format from :data:`~hiab_sim.docs_site.field_specs.KEYS`;
:func:`discrepancies` compares, at every documented mapping, the documented keys with the keys the
loader accepts (:func:`hiab_sim.docs_site.probe.accepted_keys`).
"""

from __future__ import annotations

import copy
import dataclasses
import re
from collections.abc import Callable
from typing import Any

from hiab_sim.docs_site.field_specs import KEYS, Key
from hiab_sim.docs_site.formats import FORMATS, FileFormat, Form
from hiab_sim.docs_site.markdown import table
from hiab_sim.docs_site.probe import accepted_keys, container, split
from hiab_sim.errors import HiabSimError


def key_name(segment: str) -> str:
    """A path segment's key: ``tasks[]`` -> ``tasks``, ``reference{csv}`` -> ``reference``."""
    return re.sub(r"(\[\])?(\{[^}]*\})?$", "", segment)


def parent(path: str) -> str:
    """The container path of a key path (``""`` for a top-level key)."""
    return ".".join(split(path)[:-1])


def children(keys: list[Key], container: str) -> set[str]:
    """The documented key names directly under ``container``."""
    return {key_name(split(k.path)[-1]) for k in keys if parent(k.path) == container}


def _refused(fmt: FileFormat, form: Form, key: str, path: str, documents: list[Any]) -> bool:
    """Whether ``key``, added at ``path`` to every document of ``form``, makes the loader fail on each.

    A document of ``form`` that holds the key (each one loads) shows it accepted. Otherwise the key's value
    is the one a document of another form holds there (an empty mapping if none does).
    """
    for document in documents:
        try:
            if key in container(document, path):
                return False
        except KeyError:
            continue
    donors = []
    for document in fmt.documents():
        if form.holds(document):
            continue
        try:
            node = container(document, path)
        except KeyError:
            continue
        if key in node:
            donors.append(node[key])
    value = donors[0] if donors else {}
    for document in documents:
        trial = copy.deepcopy(document)
        container(trial, path)[key] = copy.deepcopy(value)
        try:
            fmt.load(trial)
        except HiabSimError:
            continue
        return False
    return True


def _compare(fmt: FileFormat, keys: list[Key], form: Form | None) -> list[str]:
    """The differences in one form (None: a format with one form) between documented and accepted keys."""
    documents = [d for d in fmt.documents() if form is None or form.holds(d)]
    visible = [k for k in keys if form is None or k.form in ("", form.name)]
    elsewhere = {(parent(k.path), key_name(split(k.path)[-1])) for k in keys} - {
        (parent(k.path), key_name(split(k.path)[-1])) for k in visible
    }
    kinds = {"": "section"} | {k.path: k.kind for k in visible if k.kind in ("section", "names")}
    label = fmt.name if form is None else f"{fmt.name} ({form.name} form)"
    out = []
    for path, kind in kinds.items():
        accepted = accepted_keys(fmt.load, documents, path)
        documented = children(visible, path)
        where = path or "top level"
        if accepted is None:
            out.append(f"{label}: {where}: the loader accepts any key here; document it as free")
            continue
        if kind == "names":  # names another file defines: the loader checks them; the reference names none
            # (it may describe every entry under a placeholder such as <actuator>, probed with a document's first,
            # and fixed keys beside the names, e.g. a setting, which the loader must accept)
            named = [k for k in documented if not (k.startswith("<") and k.endswith(">"))]
            out += [
                f"{label}: {where}: names from another file; the loader rejects {k!r}"
                for k in named
                if k not in accepted
            ]
            continue
        for key in sorted(accepted - documented):
            if form is not None and (path, key) in elsewhere and _refused(fmt, form, key, path, documents):
                continue  # the loader's list of keys spans the forms; this form refuses the key
            out.append(f"{label}: {where}: the loader accepts {key!r}, the reference does not document it")
        for key in sorted(documented - accepted):
            out.append(f"{label}: {where}: the reference documents {key!r}, the loader rejects it")
    return out


def _memoized(load: Callable[[Any], object]) -> Callable[[Any], object]:
    """``load`` that answers a document it has seen (same keys, order and values) from memory.

    The probe loads the same document many times (once per mapping it checks, and the unchanged
    documents each time); a loader is a function of its document, so its answer (success or the error
    it raised) is the same each time.
    """
    seen: dict[str, HiabSimError | None] = {}

    def load_once(document: Any) -> object:
        key = repr(document)
        if key not in seen:
            try:
                load(document)
            except HiabSimError as error:
                seen[key] = error
                raise
            seen[key] = None
        failed = seen[key]
        if failed is not None:
            raise failed
        return None

    return load_once


def discrepancies(name: str) -> list[str]:
    """Where the documented keys of format ``name`` and the keys its loader accepts differ (empty: none).

    A format with forms (:class:`~hiab_sim.docs_site.formats.Form`) is compared per form, on that form's
    documents, with the keys documented for every form or for it; a key its loader lists but documented
    for other forms only must make the loader fail when added to this form's documents.
    """
    fmt, keys = FORMATS[name], KEYS[name]()
    fmt = dataclasses.replace(fmt, load=_memoized(fmt.load))
    out = []
    for form in fmt.forms or (None,):
        out += _compare(fmt, keys, form)
    return out


def _code(text: str) -> str:
    text = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", text)
    return text.replace("``", "`")


#: What the key column adds after a mapping whose keys the file chooses.
_MARKS = {"free": " (any key)", "names": " (names from another file)"}


def _shown(path: str) -> str:
    return f"`{path}`"


def file_formats_markdown() -> str:
    """The page: one table per file format, each row a key with type, unit, default, allowed range, meaning."""
    parts = [
        "# File formats",
        "",
        "Every key of every file hiab-sim reads, generated from the dataclasses and readers that own them "
        "(`hiab_sim/docs_site/field_specs/`, one module per format: defaults, descriptions and units from the "
        "dataclasses, ranges from their `__post_init__` checks). A test compares these keys with the keys the "
        "loaders accept: no key is missing and none is documented that a loader rejects. An unknown or missing "
        "key is a one-line `ConfigError`, a value out of range an `InvalidInputError` naming field, value and "
        "range (exit status 2).",
        "",
        "Paths: `a.b` is key `b` of mapping `a`; `links.<link>` any key of the mapping `links` (a name the file "
        "chooses); `tasks[]` an element of the list `tasks`; `reference{csv}` the "
        "mapping `reference` with `kind: csv`. A value marked `number or {value, source}` may carry its "
        'provenance: `{value: 0.268, source: "read: ..."}` with a source starting with `read`, `estimate`, '
        "`derived` or `model`. *required* keys have no default; *shared* ones default to the shared section's.",
    ]
    for name, fmt in FORMATS.items():
        rows = [
            (
                _shown(k.path) + _MARKS.get(k.kind, "") + (f" ({k.form} form)" if k.form else ""),
                k.type,
                k.unit,
                k.default or ("required" if k.kind == "value" else ""),
                _code(k.allowed),
                _code(k.description),
            )
            for k in KEYS[name]()
        ]
        parts += ["", f"## {fmt.title}", "", f"Read by `{fmt.reader}`.", ""]
        if fmt.forms:
            forms = "; ".join(f"*{f.name} form*: {_code(f.description)}" for f in fmt.forms)
            parts += [
                f"{len(fmt.forms)} forms, chosen by the top-level key: {forms}. A key marked with a form "
                "belongs to that form only (the loader refuses it in the other); unmarked keys belong to both.",
                "",
            ]
        parts.append(table(("key", "type", "unit", "default", "allowed", "description"), rows))
    return "\n".join(parts) + "\n"

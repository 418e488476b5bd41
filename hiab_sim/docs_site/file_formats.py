"""The file-format reference page and its check against the loaders.

:func:`file_formats_markdown` writes one table per format from :data:`~hiab_sim.docs_site.field_specs.KEYS`;
:func:`discrepancies` compares, at every documented mapping, the documented keys with the keys the
loader accepts (:func:`hiab_sim.docs_site.probe.accepted_keys`).
"""

from __future__ import annotations

import re

from hiab_sim.docs_site.field_specs import KEYS, Key
from hiab_sim.docs_site.formats import FORMATS
from hiab_sim.docs_site.markdown import table
from hiab_sim.docs_site.probe import accepted_keys, split


def key_name(segment: str) -> str:
    """A path segment's key: ``tasks[]`` -> ``tasks``, ``reference{csv}`` -> ``reference``."""
    return re.sub(r"(\[\])?(\{[^}]*\})?$", "", segment)


def parent(path: str) -> str:
    """The container path of a key path (``""`` for a top-level key)."""
    return ".".join(split(path)[:-1])


def children(keys: list[Key], container: str) -> set[str]:
    """The documented key names directly under ``container``."""
    return {key_name(split(k.path)[-1]) for k in keys if parent(k.path) == container}


def discrepancies(name: str) -> list[str]:
    """Where the documented keys of format ``name`` and the keys its loader accepts differ (empty: none)."""
    fmt, keys = FORMATS[name], KEYS[name]()
    documents = fmt.documents()
    containers = [""] + [k.path for k in keys if k.kind == "section"]
    out = []
    for path in containers:
        accepted = accepted_keys(fmt.load, documents, path)
        documented = children(keys, path)
        where = path or "top level"
        if accepted is None:
            out.append(f"{name}: {where}: the loader accepts any key here; document it as free")
            continue
        for key in sorted(accepted - documented):
            out.append(f"{name}: {where}: the loader accepts {key!r}, the reference does not document it")
        for key in sorted(documented - accepted):
            out.append(f"{name}: {where}: the reference documents {key!r}, the loader rejects it")
    return out


def _code(text: str) -> str:
    text = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", text)
    return text.replace("``", "`")


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
                _shown(k.path) + (" (any key)" if k.kind == "free" else ""),
                k.type,
                k.unit,
                k.default or ("required" if k.kind == "value" else ""),
                _code(k.allowed),
                _code(k.description),
            )
            for k in KEYS[name]()
        ]
        parts += ["", f"## {fmt.title}", "", f"Read by `{fmt.reader}`.", ""]
        parts.append(table(("key", "type", "unit", "default", "allowed", "description"), rows))
    return "\n".join(parts) + "\n"
